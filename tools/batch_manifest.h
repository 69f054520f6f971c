// `aerocal batch`: the manifest of a flight's work units and the records of their runs
// (docs/formats.md "Batch manifest", docs/schema/batch_manifest.schema.json).
//
// The work folder W (shared storage: the only thing units share) holds
//   W/manifest.json               the units, the `flight` arguments, the folder they are relative
//   to W/units/<id>/input.csv        a unit's measurements, every number exact (%.17g)
//   W/units/<id>/frame_run.json   its output, written atomically
//   W/done/<id>.json              done record: input hash, output hash, aerocal version, times,
//   host W/failed/<id>.json            the last failure of a unit (a success removes it)
//   W/logs/<id>.log               one line per attempt (start, done or the error)
// A unit is done when its done record names the hash of its present inputs (camera file, input
// file, stitching options, aerocal version) and of its present output: a rerun skips it; a unit
// whose inputs changed is run again; a killed one left no output, only perhaps a temporary file.
#pragma once

#include <string>
#include <vector>

namespace aerocal::tools {

struct BatchUnit {
  std::string id;     // file-name safe, unique
  std::string frame;  // the exposure it stitches
  int memory_mb = 0;  // resources of one run (an estimate from its measurements)
};

struct BatchManifest {
  std::string work;       // absolute folder of manifest.json
  std::string directory;  // absolute folder the flight's relative paths start from
  std::string version;    // aerocal version that planned it
  std::vector<std::string> flight_arguments;  // as given to `batch plan` (options of `flight`)
  std::vector<BatchUnit> units;               // in the flight's order of frames
  int merge_memory_mb = 0;

  std::string Input(const BatchUnit& unit) const;      // W/units/<id>/input.csv
  std::string Output(const BatchUnit& unit) const;     // W/units/<id>/frame_run.json
  std::string Done(const BatchUnit& unit) const;       // W/done/<id>.json
  std::string Failed(const BatchUnit& unit) const;     // W/failed/<id>.json
  std::string Log(const BatchUnit& unit) const;        // W/logs/<id>.log
  const BatchUnit& Find(const std::string& id) const;  // ConfigError("--unit: ...") when absent
};

/// Writes W/manifest.json atomically (kind "batch_manifest").
void WriteManifest(const BatchManifest& manifest);
/// Reads a manifest (FILE: what on a bad one); `work` becomes its absolute folder.
BatchManifest ReadManifest(const std::string& path);

/// 16 hex digits of the 64-bit FNV-1a hash of `text` (change detection, not security).
std::string HashText(const std::string& text);

enum class UnitState { kDone, kChanged, kFailed, kMissing };
const char* UnitStateName(UnitState state);

struct UnitRecord {
  UnitState state = UnitState::kMissing;
  double started = 0, finished = 0;  // seconds since the epoch (done units)
  std::string error;                 // failed units
};

/// The state of `unit` whose inputs hash to `input_hash` (see above).
UnitRecord ReadUnitRecord(const BatchManifest& manifest,
                          const BatchUnit& unit,
                          const std::string& input_hash);

/// Records a success (the output is already in place) or a failure, atomically, and logs it.
void RecordDone(const BatchManifest& manifest,
                const BatchUnit& unit,
                const std::string& input_hash,
                double started,
                double finished);
void RecordFailure(const BatchManifest& manifest,
                   const BatchUnit& unit,
                   const std::string& input_hash,
                   double started,
                   const std::string& error);
/// Appends one line to the unit's log (time, host, pid, `text`).
void LogUnit(const BatchManifest& manifest, const BatchUnit& unit, const std::string& text);

/// Seconds since the epoch, now.
double Now();

}  // namespace aerocal::tools
