#include "tools/batch_slurm.h"

#include "calib/core/atomic_file.h"
#include "calib/core/string_printf.h"
#include "tools/output_set.h"

#include <algorithm>
#include <filesystem>

namespace aerocal::tools {
namespace {

// `text` as one word for sh/bash, whatever it holds.
std::string Quote(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string Header(const std::string& name,
                   int memory_mb,
                   const std::string& log,
                   const SlurmOptions& o) {
  std::string h = "#!/bin/bash\n#SBATCH --job-name=" + name +
                  "\n#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  h += StringPrintf("#SBATCH --mem=%dM\n", std::max(memory_mb, 1));
  h += "#SBATCH --output=" + log + "\n";
  if (!o.partition.empty()) h += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.time_limit.empty()) h += "#SBATCH --time=" + o.time_limit + "\n";
  if (!o.account.empty()) h += "#SBATCH --account=" + o.account + "\n";
  return h;
}

}  // namespace

void WriteSlurmScripts(const BatchManifest& m,
                       const std::string& manifest_path,
                       const SlurmOptions& o) {
  namespace fs = std::filesystem;
  const std::string manifest = fs::absolute(manifest_path).string();
  int unit_memory_mb = 1;
  for (const BatchUnit& u : m.units) unit_memory_mb = std::max(unit_memory_mb, u.memory_mb);
  const std::string logs = (fs::path(m.work) / "logs").string();
  std::string units = Header("aerocal-units", unit_memory_mb, logs + "/slurm-%A_%a.out", o);
  units += StringPrintf("#SBATCH --array=0-%d", o.shards - 1);
  if (o.max_running > 0) units += StringPrintf("%%%d", o.max_running);
  units +=
      "\n# Task SLURM_ARRAY_TASK_ID runs shard ID/" + std::to_string(o.shards) +
      " of the manifest; done units are skipped, so a resubmission finishes what is missing.\n";
  units += "exec " + Quote(o.aerocal) + " batch run --manifest " + Quote(manifest) +
           " --shard \"${SLURM_ARRAY_TASK_ID}/" + std::to_string(o.shards) + "\"\n";
  std::string merge = Header("aerocal-merge", m.merge_memory_mb, logs + "/slurm-merge-%j.out", o);
  merge += "exec " + Quote(o.aerocal) + " batch merge --manifest " + Quote(manifest) + "\n";
  const std::string here = fs::absolute(o.out).string();
  std::string submit =
      "#!/bin/sh\n# Submits the units as a job array and the merge as a job that waits for all of "
      "them.\nset -e\n";
  submit += "mkdir -p " + Quote(logs) + "  # Slurm opens the tasks' output files there\n";
  submit +=
      "array=$(sbatch --parsable " + Quote(here + "/units.sbatch") + ")\narray=${array%%;*}\n";
  submit += "merge=$(sbatch --parsable --dependency=afterok:$array " +
            Quote(here + "/merge.sbatch") + ")\n";
  submit += "echo \"units: job $array, merge: job ${merge%%;*}\"\n";
  fs::create_directories(logs);
  OutputSet set(o.out);
  WriteFileAtomically(set.Staged("units.sbatch"), units);
  WriteFileAtomically(set.Staged("merge.sbatch"), merge);
  WriteFileAtomically(set.Staged("submit.sh"), submit);
  fs::permissions(set.Staged("submit.sh"),
                  fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add);
  set.Commit({"units.sbatch", "merge.sbatch", "submit.sh"});
}

}  // namespace aerocal::tools
