// `aerocal batch slurm`: the Slurm job scripts of a manifest. units.sbatch is a job array of
// `--array=0-(N-1)%K` tasks, task SLURM_ARRAY_TASK_ID running shard ID/N; merge.sbatch runs the
// merge; submit.sh submits both, the merge as a job that starts only after every task ended well
// (`--dependency=afterok:ARRAY`). Memory per task: the largest unit estimate of the plan (a shard
// runs its units one after the other).
#pragma once

#include "tools/batch_manifest.h"

#include <string>

namespace aerocal::tools {

struct SlurmOptions {
  int shards = 1;                              // array tasks N, 1..100000
  int max_running = 0;                         // K: tasks running at once (0: no limit)
  std::string partition, time_limit, account;  // empty: the cluster's default
  std::string aerocal;                         // the executable the jobs run (absolute path)
  std::string out;                             // folder of the scripts
};

/// Writes OUT/units.sbatch, OUT/merge.sbatch and OUT/submit.sh (an output set: all or none).
void WriteSlurmScripts(const BatchManifest& manifest,
                       const std::string& manifest_path,
                       const SlurmOptions& options);

}  // namespace aerocal::tools
