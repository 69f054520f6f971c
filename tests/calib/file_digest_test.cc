// SHA-256 of calib/core/file_digest.h against the FIPS 180-4 / NIST example vectors, and the
// result key `inputs` it writes.
#include "calib/core/file_digest.h"

#include "calib/core/error.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace aerocal {
namespace {

TEST(Sha256Hex, NistExampleVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  // 448 bits: the padding needs a second block.
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // One million 'a' (FIPS 180-4 example; many full blocks).
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(InputFilesToJson, SizesChecksumsEachPathOnce) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "aerocal_file_digest_test";
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "points.csv").string();
  std::ofstream(file) << "abc";
  const nlohmann::json inputs = InputFilesToJson({{"points", file}, {"again", file}, {"none", ""}});
  ASSERT_EQ(inputs.size(), 1u);
  EXPECT_EQ(inputs[0]["role"], "points");
  EXPECT_EQ(inputs[0]["bytes"], 3);
  EXPECT_EQ(inputs[0]["sha256"],
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_THROW(InputFilesToJson({{"missing", (dir / "missing.csv").string()}}), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace aerocal
