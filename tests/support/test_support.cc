#include "tests/support/test_support.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/json_schema.h"
#include "calib/core/result_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <random>
#include <regex>
#include <sys/wait.h>
#include <unistd.h>

namespace aerocal::testing {

TempDir::TempDir(const std::string& prefix) {
  std::random_device device;
  const auto base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    const auto candidate =
        base / (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(device()));
    if (std::filesystem::create_directory(candidate)) {
      path_ = candidate.string();
      return;
    }
  }
  path_ = (base / prefix).string();
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  if (!std::getenv("AEROCAL_KEEP_TEST_FILES")) std::filesystem::remove_all(path_, ec);
}

CommandResult RunCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string AerocalBinary() { return AEROCAL_BINARY; }

CommandResult RunAerocal(const std::string& arguments) {
  return RunCommand(AerocalBinary() + " " + arguments);
}

double XmpAttribute(const std::string& bytes, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(bytes, m, std::regex(":" + name + "=\"([^\"]+)\""))) return NAN;
  return std::stod(m[1].str());
}

std::string SharedDataDir(const std::string& name) {
  const std::string dir = std::string(AEROCAL_SHARED_DATA_DIR) + "/" + name;
  return std::filesystem::is_directory(dir) ? dir : "";
}

nlohmann::json ReadJson(const std::string& path) {
  nlohmann::json document = ReadJsonFile(path);
  // A result of a command: every test that reads one checks it against its kind's schema.
  if (document.is_object() && document.contains("kind") && document.contains("schema_version"))
    ExpectValidResult(document, path);
  return document;
}

std::string SchemaPath(const std::string& kind) {
  return std::string(AEROCAL_SCHEMA_DIR) + "/" + kind + ".schema.json";
}

void ExpectValidResult(const nlohmann::json& document, const std::string& path) {
  try {
    ValidateResult(document, path, AEROCAL_SCHEMA_DIR);
  } catch (const std::exception& e) {  // InputError: the document; LogicError: the schema
    ADD_FAILURE() << "result does not match its schema in docs/schema: " << e.what();
  }
}

void ExpectValidResult(const std::string& path) { ExpectValidResult(ReadJsonFile(path), path); }

std::string ResultWithoutClock(const std::string& path) {
  std::function<void(nlohmann::json&)> strip = [&](nlohmann::json& j) {
    if (j.is_object()) {
      for (const char* clock : {"seconds", "timing", "seconds_testing"}) j.erase(clock);
      for (auto& [key, value] : j.items()) strip(value);
    } else if (j.is_array()) {
      for (auto& value : j) strip(value);
    }
  };
  nlohmann::json document = ReadJsonFile(path);
  strip(document);
  return document.dump(1);
}

}  // namespace aerocal::testing
