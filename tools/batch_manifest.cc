#include "tools/batch_manifest.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/json_schema.h"
#include "calib/core/result_file.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <unistd.h>

namespace aerocal::tools {
namespace {

namespace fs = std::filesystem;

std::string Join(const std::string& a, const std::string& b) { return (fs::path(a) / b).string(); }

std::string HostName() {
  char name[256] = {0};
  if (::gethostname(name, sizeof(name) - 1) != 0) return "?";
  return name;
}

std::string TimeText(double seconds) {
  const std::time_t t = static_cast<std::time_t>(seconds);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return text;
}

}  // namespace

double Now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string BatchManifest::Input(const BatchUnit& u) const {
  return Join(work, "units/" + u.id + "/input.csv");
}
std::string BatchManifest::Output(const BatchUnit& u) const {
  return Join(work, "units/" + u.id + "/frame_run.json");
}
std::string BatchManifest::Done(const BatchUnit& u) const {
  return Join(work, "done/" + u.id + ".json");
}
std::string BatchManifest::Failed(const BatchUnit& u) const {
  return Join(work, "failed/" + u.id + ".json");
}
std::string BatchManifest::Log(const BatchUnit& u) const {
  return Join(work, "logs/" + u.id + ".log");
}

const BatchUnit& BatchManifest::Find(const std::string& id) const {
  for (const BatchUnit& u : units)
    if (u.id == id) return u;
  throw ConfigError("--unit: no unit '" + id + "' in " + Join(work, "manifest.json"));
}

void WriteManifest(const BatchManifest& m) {
  nlohmann::json units = nlohmann::json::array();
  for (const BatchUnit& u : m.units)
    units.push_back({{"id", u.id},
                     {"kind", "stitch_frame"},
                     {"frame", u.frame},
                     {"input", "units/" + u.id + "/input.csv"},
                     {"output", "units/" + u.id + "/frame_run.json"},
                     {"resources", {{"cpus", 1}, {"memory_mb", u.memory_mb}}}});
  const nlohmann::json doc = {
      {"aerocal_version", m.version},
      {"directory", m.directory},
      {"flight_arguments", m.flight_arguments},
      {"units", units},
      {"merge", {{"resources", {{"cpus", 1}, {"memory_mb", m.merge_memory_mb}}}}}};
  WriteResult(Join(m.work, "manifest.json"), "batch_manifest", doc);
}

BatchManifest ReadManifest(const std::string& path) {
  const nlohmann::json doc = ReadResult(path, {"batch_manifest"}, "`aerocal batch plan`");
  ValidateJson(
      doc, ReadJsonSchema(std::string(AEROCAL_SCHEMA_DIR) + "/batch_manifest.schema.json"), path);
  BatchManifest m;
  try {
    m.work = fs::absolute(fs::path(path)).parent_path().string();
    m.directory = doc.at("directory").get<std::string>();
    m.version = doc.at("aerocal_version").get<std::string>();
    m.flight_arguments = doc.at("flight_arguments").get<std::vector<std::string>>();
    m.merge_memory_mb = doc.at("merge").at("resources").at("memory_mb").get<int>();
    for (const auto& u : doc.at("units"))
      m.units.push_back({u.at("id").get<std::string>(),
                         u.at("frame").get<std::string>(),
                         u.at("resources").at("memory_mb").get<int>()});
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a batch manifest (" + e.what() + ")");
  }
  // A unit's files are named by its id inside W: a plain file name, one unit each.
  std::set<std::string> ids;
  for (size_t i = 0; i < m.units.size(); ++i) {
    const std::string& id = m.units[i].id;
    const bool plain =
        !id.empty() && id != "." && id != ".." &&
        id.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-") ==
            std::string::npos;
    if (!plain || !ids.insert(id).second)
      throw InputError(path + ": units[" + std::to_string(i) +
                       "].id: expected a unique name of letters, digits, "
                       "'.', '_', '-' (got '" +
                       id + "')");
  }
  return m;
}

std::string HashText(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64: offset basis and prime
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

const char* UnitStateName(UnitState state) {
  switch (state) {
    case UnitState::kDone:
      return "done";
    case UnitState::kChanged:
      return "changed";
    case UnitState::kFailed:
      return "failed";
    case UnitState::kMissing:
      return "missing";
  }
  return "?";
}

UnitRecord ReadUnitRecord(const BatchManifest& m,
                          const BatchUnit& unit,
                          const std::string& input_hash) {
  UnitRecord r;
  std::error_code ec;
  if (fs::is_regular_file(m.Done(unit), ec)) {
    const nlohmann::json done = nlohmann::json::parse(ReadTextFile(m.Done(unit)), nullptr, false);
    const bool output = fs::is_regular_file(m.Output(unit), ec);
    if (!done.is_discarded() && output && done.value("input_hash", "") == input_hash &&
        done.value("output_hash", "") == HashText(ReadTextFile(m.Output(unit)))) {
      r.state = UnitState::kDone;
      r.started = done.value("started", 0.0);
      r.finished = done.value("finished", 0.0);
      return r;
    }
    r.state = UnitState::kChanged;
  }
  if (fs::is_regular_file(m.Failed(unit), ec)) {
    const nlohmann::json failed =
        nlohmann::json::parse(ReadTextFile(m.Failed(unit)), nullptr, false);
    if (!failed.is_discarded() && failed.value("input_hash", "") == input_hash) {
      r.state = UnitState::kFailed;
      r.error = failed.value("error", "");
    }
  }
  return r;
}

void LogUnit(const BatchManifest& m, const BatchUnit& unit, const std::string& text) {
  fs::create_directories(fs::path(m.Log(unit)).parent_path());
  std::ofstream log(m.Log(unit), std::ios::app);
  log << TimeText(Now()) << ' ' << HostName() << " pid " << ::getpid() << ": " << text << '\n';
}

void RecordDone(const BatchManifest& m,
                const BatchUnit& unit,
                const std::string& input_hash,
                double started,
                double finished) {
  const nlohmann::json done = {{"unit", unit.id},
                               {"input_hash", input_hash},
                               {"output_hash", HashText(ReadTextFile(m.Output(unit)))},
                               {"aerocal_version", AEROCAL_VERSION},
                               {"host", HostName()},
                               {"started", started},
                               {"finished", finished}};
  WriteFileAtomically(m.Done(unit), done.dump(2) + "\n");
  std::error_code ignored;
  fs::remove(m.Failed(unit), ignored);
  char line[64];
  std::snprintf(line, sizeof(line), "done in %.2f s", finished - started);
  LogUnit(m, unit, line);
}

void RecordFailure(const BatchManifest& m,
                   const BatchUnit& unit,
                   const std::string& input_hash,
                   double started,
                   const std::string& error) {
  const nlohmann::json failed = {{"unit", unit.id},
                                 {"input_hash", input_hash},
                                 {"error", error},
                                 {"aerocal_version", AEROCAL_VERSION},
                                 {"host", HostName()},
                                 {"started", started},
                                 {"failed", Now()}};
  WriteFileAtomically(m.Failed(unit), failed.dump(2) + "\n");
  LogUnit(m, unit, "failed: " + error);
}

}  // namespace aerocal::tools
