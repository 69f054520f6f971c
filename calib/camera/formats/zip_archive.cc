// ZIP members with zlib's raw inflate (zip_archive.h).
#include "calib/camera/formats/zip_archive.h"

#include "calib/core/error.h"

#include <cstdint>
#include <zlib.h>

namespace aerocal::calib::internal {
namespace {

constexpr uint32_t kLocalHeader = 0x04034b50, kCentralHeader = 0x02014b50, kEnd = 0x06054b50;
constexpr size_t kMaxMemberBytes = size_t{256} << 20;

uint32_t Le(const std::string& b, size_t at, int n) {
  uint32_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
  return v;
}

struct Member {
  std::string name;
  uint32_t method, compressed, size, local_offset;
};

std::vector<Member> Members(const std::string& b, const std::string& where) {
  const auto fail = [&](const std::string& what) -> void {
    throw InputError(where + ": not a readable ZIP archive (" + what + ")");
  };
  if (b.size() < 22) fail("shorter than an end record");
  size_t end = std::string::npos;
  for (size_t at = b.size() - 22 + 1; at-- > 0 && b.size() - at <= 22 + 65535;)
    if (Le(b, at, 4) == kEnd) {
      end = at;
      break;
    }
  if (end == std::string::npos) fail("no end-of-central-directory record");
  const uint32_t count = Le(b, end + 10, 2), offset = Le(b, end + 16, 4);
  if (count == 0xffff || offset == 0xffffffff) fail("ZIP64 is not supported");
  std::vector<Member> members;
  size_t at = offset;
  for (uint32_t k = 0; k < count; ++k) {
    if (at > b.size() || b.size() - at < 46 || Le(b, at, 4) != kCentralHeader)
      fail("central directory entry " + std::to_string(k) + " out of the file");
    Member m{"", Le(b, at + 10, 2), Le(b, at + 20, 4), Le(b, at + 24, 4), Le(b, at + 42, 4)};
    if (Le(b, at + 8, 2) & 1) fail("encrypted members are not supported");
    const size_t name_length = Le(b, at + 28, 2);
    const size_t skip = 46 + name_length + Le(b, at + 30, 2) + Le(b, at + 32, 2);
    if (b.size() - at < skip) fail("central directory entry " + std::to_string(k) + " truncated");
    m.name = b.substr(at + 46, name_length);
    members.push_back(m);
    at += skip;
  }
  return members;
}

}  // namespace

bool LooksLikeZip(const std::string& bytes) {
  return bytes.size() >= 4 && Le(bytes, 0, 4) == kLocalHeader;
}

std::vector<std::string> ZipMemberNames(const std::string& bytes, const std::string& where) {
  std::vector<std::string> names;
  for (const Member& m : Members(bytes, where)) names.push_back(m.name);
  return names;
}

std::string ReadZipMember(const std::string& b, const std::string& name, const std::string& where) {
  const std::vector<Member> members = Members(b, where);
  const Member* found = nullptr;
  std::string names;
  for (const Member& m : members) {
    names += (names.empty() ? "" : ", ") + m.name;
    if (m.name == name) {
      if (found) throw InputError(where + ": member " + name + " occurs twice in the archive");
      found = &m;
    }
  }
  if (!found)
    throw InputError(where + ": the archive has no " + name + " (members: " + names + ")");
  const std::string what = where + ": member " + name;
  const size_t at = found->local_offset;
  if (at > b.size() || b.size() - at < 30 || Le(b, at, 4) != kLocalHeader)
    throw InputError(what + ": local header out of the file");
  const size_t data = at + 30 + Le(b, at + 26, 2) + Le(b, at + 28, 2);
  if (data > b.size() || b.size() - data < found->compressed)
    throw InputError(what + ": data runs past the end of the archive");
  if (found->size > kMaxMemberBytes) throw InputError(what + ": larger than 256 MiB");
  // Deflate expands at most about 1032:1: a larger stated size is a damaged header.
  if (found->size > uint64_t{found->compressed} * 1100 + 1024)
    throw InputError(what + ": stated size " + std::to_string(found->size) +
                     " bytes does not fit its " + std::to_string(found->compressed) +
                     " compressed bytes");
  if (found->method == 0) {
    if (found->compressed != found->size) throw InputError(what + ": stored sizes disagree");
    return b.substr(data, found->size);
  }
  if (found->method != 8)
    throw InputError(what + ": compression method " + std::to_string(found->method) +
                     " is not supported (stored, deflate)");
  std::string out(found->size, '\0');
  z_stream z{};
  if (inflateInit2(&z, -MAX_WBITS) != Z_OK) throw InputError(what + ": zlib cannot start");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(b.data() + data));
  z.avail_in = found->compressed;
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = found->size;
  const int status = inflate(&z, Z_FINISH);
  const uLong produced = z.total_out;
  inflateEnd(&z);
  if (status != Z_STREAM_END || produced != found->size)
    throw InputError(what + ": deflate data are corrupt or their size is not the stated " +
                     std::to_string(found->size) + " bytes");
  return out;
}

}  // namespace aerocal::calib::internal
