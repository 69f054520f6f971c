// Reading one member of a ZIP archive (PKWARE APPNOTE 6.3: end of central directory, central
// directory, local headers; stored or deflated members, no ZIP64, no encryption), for the camera
// files that tools ship inside archives: a Metashape / PhotoScan .psz project and the chunk.zip of
// a .psx project folder. InputError("ARCHIVE: ...") on anything else, never a crash.
#pragma once

#include <string>
#include <vector>

namespace aerocal::calib::internal {

/// True when `bytes` start with a ZIP local-file header ("PK\3\4").
bool LooksLikeZip(const std::string& bytes);

/// The names of the archive's members, in central-directory order.
std::vector<std::string> ZipMemberNames(const std::string& bytes, const std::string& where);

/// The uncompressed bytes of member `name` (InputError naming `where` and the members when it is
/// absent or cannot be read; members above 256 MiB are refused).
std::string ReadZipMember(const std::string& bytes,
                          const std::string& name,
                          const std::string& where);

}  // namespace aerocal::calib::internal
