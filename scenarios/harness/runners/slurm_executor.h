#pragma once
// Batches on a Slurm cluster. The batches handed over at once (a `run`, every point of a `sweep`,
// one evaluation of a `tune`) become one job array: each array task runs one shard of one batch
// (`trimbot run --shard i/n`, by default one trial per task) into a shared work folder; this
// process waits for the array, resubmits the tasks that failed (killed, out of time, node lost,
// crashed: every exit code above 1 or no summary left), and merges each batch's shards into the
// batch's output folder, so summary.json is byte-identical to a local run of the same seeds.
// A task that still fails after its retries is reported with its trials' seeds and log, and its
// trials count as failed in the merged batch (never silently lost).
//
// A visual map the scenarios build on first use (visual_map: {mapping_drive: ...}) is built once
// by a job of its own that the array waits for (afterok), into the map cache
// ($TRIMBOT_MAP_CACHE, which must be a folder every node sees), and shared by every task.
//
// Work folder (shared; by default the command's --out with ".slurm" appended):
//   submission_NNN/tasks.txt            one command line per array task
//   submission_NNN/array.sbatch         the array job's script (sbatch it by hand to rerun)
//   submission_NNN/batches/BBB/shard_SSS/   each task's output (a `trimbot run --shard` folder)
//   submission_NNN/status/TTT.exit      each task's exit code, written as it ends
//   submission_NNN/logs/                each attempt's output; the map job's
// Kubernetes users: docs/cluster.md and docs/kubernetes/indexed_job.yaml show the Indexed Job equivalent.
#include <string>
#include <vector>

#include "loop/setting.h"
#include "runners/batch_executor.h"

namespace trimbot::scenarios {

struct SlurmOptions {
  std::string partition;      // empty: the cluster's default partition
  int max_jobs = 0;           // array tasks running at once (sbatch --array=...%N); 0: no limit
  int trials_per_task = 1;    // trials each task runs (a shard of the batch)
  int cpus_per_task = 1;      // sbatch --cpus-per-task, and the task's --jobs
  int retries = 1;            // resubmissions of a failed task before it is reported failed
  std::string work_dir;       // shared work folder (see above)
  double poll_seconds = 5.0;  // how often the array's state is read
  std::string trimbot;        // the binary the tasks run (default: this one)
};

class SlurmExecutor : public BatchExecutor {
 public:
  // Checks, before anything is submitted or written to an output folder: the Slurm commands are
  // there and the controller answers, the partition exists, the work folder and the output
  // folders' parents are writable. Throws InputError naming the option (exit code 2).
  SlurmExecutor(SlurmOptions options, ProjectPaths paths, const std::vector<std::string>& out_dirs);
  std::vector<int> Run(const std::vector<BatchOptions>& batches, const BatchDone& done = {}) override;

 private:
  SlurmOptions options_;
  ProjectPaths paths_;
  int submissions_ = 0;
};

// Runs `argv` (no shell) and returns its exit code with stdout and stderr in `output`; -1 when it
// cannot be started (not installed). Used for sbatch, squeue, sinfo, scancel.
int RunCommand(const std::vector<std::string>& argv, std::string& output);

// `text` quoted for a POSIX shell: 'text' with every ' written as '\''.
std::string ShellQuote(const std::string& text);

}  // namespace trimbot::scenarios
