#include "runners/slurm_executor.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "runners/map_cache.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

std::string Index(int i, int width = 3) {
  std::ostringstream name;
  name << std::setw(width) << std::setfill('0') << i;
  return name.str();
}

std::string FirstLine(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "(no output)" : line;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

std::string Joined(const std::vector<std::string>& words, const std::string& separator) {
  std::string text;
  for (const auto& w : words) text += (text.empty() ? "" : separator) + w;
  return text;
}

// The controller answers and lists its partitions (sinfo's %R: names without the default's '*').
std::set<std::string> Partitions() {
  std::string output;
  const int code = RunCommand({"sinfo", "--noheader", "--format=%R"}, output);
  if (code == -1) throw InputError("--slurm", "Slurm's commands are not installed here (sinfo not found)");
  if (code != 0) throw InputError("--slurm", "Slurm is not reachable: sinfo: " + FirstLine(output));
  const std::vector<std::string> lines = Lines(output);
  return {lines.begin(), lines.end()};
}

// A folder that can be written: created if missing, and a file made and removed in it.
void CheckWritableFolder(const std::string& dir, const std::string& option) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw InputError(option, dir + ": cannot create the folder: " + error.message());
  const std::string probe = dir + "/.trimbot_write_check_" + std::to_string(getpid());
  if (!std::ofstream(probe) || !fs::remove(probe, error)) throw InputError(option, dir + ": not writable");
}

// The folder an output folder will be created in (its nearest existing ancestor) can be written,
// so the merge at the end cannot fail after the cluster did the work. Nothing is created.
void CheckOutputParent(const std::string& out_dir) {
  fs::path dir = fs::absolute(out_dir).parent_path();
  while (!dir.empty() && !fs::exists(dir)) dir = dir.parent_path();
  const std::string probe = (dir / (".trimbot_write_check_" + std::to_string(getpid()))).string();
  std::error_code error;
  if (!fs::is_directory(dir) || !std::ofstream(probe) || !fs::remove(probe, error)) {
    throw InputError("--out", out_dir + ": " + dir.string() + " is not a writable folder");
  }
}

// One array task: a shard of one batch.
struct Task {
  int batch = 0;
  std::string dir;      // the shard's output folder
  std::string command;  // shell command line
  std::vector<int> trials;
  std::vector<std::uint64_t> seeds;
  int attempts = 0;
  std::string failure;  // why the last attempt failed; empty when it succeeded
};

std::string CommandLine(const std::vector<std::string>& argv) {
  std::vector<std::string> quoted;
  for (const auto& a : argv) quoted.push_back(ShellQuote(a));
  return Joined(quoted, " ");
}

// A map job for every visual map the batches build on first use and the cache does not hold.
// Returns "" or the dependency list "afterok:ID:ID".
std::string SubmitMissingMaps(const std::vector<BatchOptions>& batches, const std::vector<Scenario>& scenarios,
                              const ProjectPaths& paths, const std::vector<std::string>& sbatch_common,
                              const std::string& trimbot, const std::string& work) {
  std::set<std::string> submitted;
  std::vector<std::string> jobs;
  for (std::size_t b = 0; b < batches.size(); ++b) {
    const std::optional<MapRecipe> recipe = VisualMapRecipe(scenarios[b], paths);
    if (!recipe || !FindCachedMap(*recipe, paths, DefaultMapCacheDir()).empty()) continue;
    CheckWritableFolder(DefaultMapCacheDir(), "TRIMBOT_MAP_CACHE");
    const std::string id = MapCacheId(MapCacheKey(*recipe, paths));
    if (!submitted.insert(id).second) continue;
    std::vector<std::string> ensure = {trimbot, "--data-root", paths.root,
                                       "map",   "ensure",      fs::absolute(batches[b].scenario_path).string()};
    for (const auto& o : batches[b].overrides) ensure.insert(ensure.end(), {"--set", o});
    std::vector<std::string> argv = sbatch_common;
    argv.insert(argv.end(),
                {"--job-name=trimbot-map", "--output=" + work + "/logs/map_" + id + ".out",
                 "--export=ALL,TRIMBOT_MAP_CACHE=" + DefaultMapCacheDir(), "--wrap=" + CommandLine(ensure)});
    std::string output;
    if (RunCommand(argv, output) != 0) throw std::runtime_error("sbatch of the map job failed: " + FirstLine(output));
    jobs.push_back(FirstLine(output).substr(0, FirstLine(output).find(';')));
    std::cout << "[slurm] map " << id << " is not cached: job " << jobs.back() << " builds it into "
              << DefaultMapCacheDir() << " before the trials" << std::endl;
  }
  return jobs.empty() ? "" : "afterok:" + Joined(jobs, ":");
}

std::string ArrayScript(const std::string& work) {
  return "#!/bin/bash\n"
         "# An array task of `trimbot` (scenarios/harness/runners/slurm_executor.h): runs line SLURM_ARRAY_TASK_ID + "
         "1\n"
         "# of tasks.txt and records its exit code in status/.\n"
         "set -u\n"
         "work=" +
         ShellQuote(work) +
         "\n"
         "export TRIMBOT_MAP_CACHE=" +
         ShellQuote(DefaultMapCacheDir()) +
         "\n"
         "command=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" \"$work/tasks.txt\")\n"
         "eval \"$command\"\n"
         "code=$?\n"
         "echo \"$code\" > \"$work/status/$SLURM_ARRAY_TASK_ID.exit.partial\"\n"
         "mv \"$work/status/$SLURM_ARRAY_TASK_ID.exit.partial\" \"$work/status/$SLURM_ARRAY_TASK_ID.exit\"\n"
         "# 0 and 1 are results (1: a criterion failed in this shard); anything else is the task's failure.\n"
         "if [ \"$code\" -le 1 ]; then exit 0; fi\n"
         "exit \"$code\"\n";
}

// Waits until the array job has no task left in the queue, printing its progress.
void WaitForArray(const std::string& job, const std::string& work, std::size_t tasks, double poll_seconds) {
  std::string last;
  int failures = 0;
  while (true) {
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_seconds));
    std::string output;
    const int code = RunCommand({"squeue", "--noheader", "--jobs=" + job, "--format=%T"}, output);
    if (code != 0 && output.find("Invalid job id") == std::string::npos) {
      if (++failures >= 12) {
        throw std::runtime_error("squeue failed 12 times in a row (" + FirstLine(output) + "); job " + job +
                                 " may still run, its outputs go to " + work);
      }
      continue;
    }
    failures = 0;
    std::map<std::string, int> states;
    for (const auto& state : Lines(code == 0 ? output : "")) ++states[state];
    std::size_t ended = 0;
    for (const auto& entry : fs::directory_iterator(work + "/status")) ended += entry.path().extension() == ".exit";
    std::ostringstream line;
    line << "[slurm] job " << job << ": " << ended << "/" << tasks << " tasks ended";
    for (const auto& [state, count] : states) line << ", " << count << " " << state;
    if (line.str() != last) std::cout << line.str() << std::endl;
    last = line.str();
    if (states.empty()) return;
  }
}

// Why a task's attempt failed, or "" when it left a result.
std::string TaskFailure(const Task& task, int index, const std::string& work) {
  std::ifstream status(work + "/status/" + std::to_string(index) + ".exit");
  int code = -1;
  if (!(status >> code)) return "no exit status (cancelled, killed, out of time, or its node was lost)";
  if (code > 1) return "exit code " + std::to_string(code);
  if (!fs::exists(task.dir + "/summary.json")) return "exit code " + std::to_string(code) + " but no summary.json";
  return "";
}

// The array's tasks: each batch cut into shards of trials_per_task trials.
std::vector<Task> PlanTasks(const std::vector<BatchOptions>& batches, const std::vector<Scenario>& scenarios,
                            const SlurmOptions& options, const ProjectPaths& paths, const std::string& work) {
  std::vector<Task> tasks;
  for (std::size_t b = 0; b < batches.size(); ++b) {
    const BatchOptions& batch = batches[b];
    const int trials = batch.trials.value_or(scenarios[b].trials);
    const std::uint64_t seed = batch.seed.value_or(scenarios[b].setting.seed);
    const int shards = (trials + options.trials_per_task - 1) / options.trials_per_task;
    for (int shard = 0; shard < shards; ++shard) {
      Task task;
      task.batch = static_cast<int>(b);
      task.dir = work + "/batches/" + Index(static_cast<int>(b)) + "/shard_" + Index(shard);
      for (int i = shard; i < trials; i += shards) {
        task.trials.push_back(i);
        task.seeds.push_back(seed + static_cast<std::uint64_t>(i));
      }
      std::vector<std::string> argv = {options.trimbot,
                                       "--data-root",
                                       paths.root,
                                       "run",
                                       fs::absolute(batch.scenario_path).string(),
                                       "--out",
                                       task.dir,
                                       "--shard",
                                       std::to_string(shard) + "/" + std::to_string(shards),
                                       "--trials",
                                       std::to_string(trials),
                                       "--seed",
                                       std::to_string(seed),
                                       "--jobs",
                                       std::to_string(options.cpus_per_task)};
      for (const auto& o : batch.overrides) argv.insert(argv.end(), {"--set", o});
      // What each trial records, as asked of the batch.
      if (batch.video) argv.emplace_back("--video");
      if (!batch.bag) argv.emplace_back("--no-bag");
      if (batch.keep_worlds) argv.emplace_back("--keep-worlds");
      task.command = CommandLine(argv);
      tasks.push_back(task);
    }
  }
  return tasks;
}

std::vector<std::string> SbatchCommon(const SlurmOptions& options) {
  std::vector<std::string> argv = {"sbatch", "--parsable", "--cpus-per-task=" + std::to_string(options.cpus_per_task)};
  if (!options.partition.empty()) argv.push_back("--partition=" + options.partition);
  return argv;
}

// Submits the `pending` tasks as one array job; returns its id.
std::string SubmitArray(const std::vector<int>& pending, int attempt, const std::vector<Scenario>& scenarios,
                        const std::string& dependency, const SlurmOptions& options, const std::string& work) {
  // Each task's trials one round after another on its CPUs, each within the scenario's wall-clock limit.
  double wall_limit = 0.0;
  for (const auto& s : scenarios) wall_limit = std::max(wall_limit, s.wall_time_limit);
  const int rounds = (options.trials_per_task + options.cpus_per_task - 1) / options.cpus_per_task;
  const int minutes = static_cast<int>(std::ceil(rounds * wall_limit / 60.0)) + 10;
  std::vector<std::string> ids;
  for (const int i : pending) ids.push_back(std::to_string(i));
  std::vector<std::string> argv = SbatchCommon(options);
  argv.push_back("--array=" + Joined(ids, ",") + (options.max_jobs > 0 ? "%" + std::to_string(options.max_jobs) : ""));
  argv.push_back("--job-name=trimbot-" + scenarios.front().name);
  argv.push_back("--time=" + std::to_string(minutes));
  argv.push_back("--output=" + work + "/logs/task_%a.attempt_" + std::to_string(attempt) + ".out");
  if (!dependency.empty()) argv.insert(argv.end(), {"--dependency=" + dependency, "--kill-on-invalid-dep=yes"});
  argv.push_back(work + "/array.sbatch");
  std::string output;
  if (RunCommand(argv, output) != 0) throw std::runtime_error("sbatch failed: " + FirstLine(output));
  return FirstLine(output).substr(0, FirstLine(output).find(';'));
}

// The pending tasks that failed this attempt, each reported with its trials' seeds and its log.
std::vector<int> CollectFailures(std::vector<Task>& tasks, const std::vector<int>& pending, int attempt, int retries,
                                 const std::string& work) {
  std::vector<int> failed;
  for (const int i : pending) {
    tasks[i].failure = TaskFailure(tasks[i], i, work);
    if (tasks[i].failure.empty()) continue;
    failed.push_back(i);
    std::cout << "[slurm] task " << i << " (batch " << tasks[i].batch << ", trials";
    for (std::size_t k = 0; k < tasks[i].trials.size(); ++k)
      std::cout << " " << tasks[i].trials[k] << " seed " << tasks[i].seeds[k];
    std::cout << ") failed: " << tasks[i].failure << "; log " << work << "/logs/task_" << i << ".attempt_" << attempt
              << ".out" << (attempt < retries ? "; resubmitting" : "") << std::endl;
  }
  return failed;
}

void WriteTaskRecord(const std::vector<Task>& tasks, const std::string& path) {
  nlohmann::json record = nlohmann::json::array();
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    record.push_back({{"task", i},
                      {"batch", tasks[i].batch},
                      {"trials", tasks[i].trials},
                      {"seeds", tasks[i].seeds},
                      {"attempts", tasks[i].attempts},
                      {"failure", tasks[i].failure},
                      {"command", tasks[i].command}});
  }
  WriteFileAtomically(path, record.dump(2));
}

}  // namespace

std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

int RunCommand(const std::vector<std::string>& argv, std::string& output) {
  output.clear();
  FILE* pipe = popen((CommandLine(argv) + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buffer[4096];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, n);
  const int status = pclose(pipe);
  if (!WIFEXITED(status)) return -1;
  return WEXITSTATUS(status) == 127 ? -1 : WEXITSTATUS(status);  // 127: the shell found no such command
}

SlurmExecutor::SlurmExecutor(SlurmOptions options, ProjectPaths paths, const std::vector<std::string>& out_dirs)
    : options_(std::move(options)), paths_(std::move(paths)) {
  const std::set<std::string> partitions = Partitions();
  if (!options_.partition.empty() && partitions.count(options_.partition) == 0) {
    throw InputError("--partition", "partition '" + options_.partition +
                                        "' does not exist on this cluster (partitions: " +
                                        Joined({partitions.begin(), partitions.end()}, ", ") + ")");
  }
  if (options_.work_dir.empty()) throw InputError("--work-dir", "no work folder given");
  options_.work_dir = fs::absolute(options_.work_dir).string();
  CheckWritableFolder(options_.work_dir, "--work-dir");
  for (const auto& out : out_dirs) CheckOutputParent(out);
  if (options_.trimbot.empty()) options_.trimbot = fs::read_symlink("/proc/self/exe").string();
  paths_.root = fs::absolute(paths_.root).string();
}

std::vector<int> SlurmExecutor::Run(const std::vector<BatchOptions>& batches, const BatchDone& done) {
  // Every batch's scenario is checked here before anything is submitted.
  std::vector<Scenario> scenarios;
  for (const auto& batch : batches) scenarios.push_back(LoadBatchInputs(batch).scenario);
  const std::string work = options_.work_dir + "/submission_" + Index(submissions_++);
  fs::remove_all(work);
  for (const char* sub : {"logs", "status", "batches"}) fs::create_directories(work + "/" + sub);
  std::vector<Task> tasks = PlanTasks(batches, scenarios, options_, paths_, work);
  std::string task_lines;
  for (const auto& t : tasks) task_lines += t.command + "\n";
  WriteFileAtomically(work + "/tasks.txt", task_lines);
  WriteFileAtomically(work + "/array.sbatch", ArrayScript(work));

  std::vector<int> pending(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) pending[i] = static_cast<int>(i);
  for (int attempt = 0; attempt <= options_.retries && !pending.empty(); ++attempt) {
    for (const int i : pending) {
      fs::remove_all(tasks[i].dir);
      fs::remove(work + "/status/" + std::to_string(i) + ".exit");
      ++tasks[i].attempts;
    }
    const std::vector<std::string> common = SbatchCommon(options_);
    const std::string dependency = SubmitMissingMaps(batches, scenarios, paths_, common, options_.trimbot, work);
    const std::string job = SubmitArray(pending, attempt, scenarios, dependency, options_, work);
    std::cout << "[slurm] submitted job " << job << ": " << pending.size() << " tasks of " << batches.size()
              << (batches.size() == 1 ? " batch" : " batches") << " (attempt " << attempt + 1 << " of "
              << options_.retries + 1 << "), work folder " << work << std::endl;
    WaitForArray(job, work, tasks.size(), options_.poll_seconds);
    pending = CollectFailures(tasks, pending, attempt, options_.retries, work);
  }
  WriteTaskRecord(tasks, work + "/tasks.json");

  std::vector<int> codes;
  for (std::size_t b = 0; b < batches.size(); ++b) {
    std::vector<std::string> shards;
    for (const auto& t : tasks) {
      if (t.batch == static_cast<int>(b) && t.failure.empty()) shards.push_back(t.dir);
    }
    if (shards.empty()) {
      throw std::runtime_error("every task of batch " + std::to_string(b) + " (" + batches[b].out_dir +
                               ") failed; see " + work + "/tasks.json and " + work + "/logs/");
    }
    codes.push_back(MergeShards(shards, batches[b].out_dir, paths_, batches[b].quiet));
    if (done) done(b);
  }
  if (!pending.empty()) {
    std::cout << "[slurm] " << pending.size() << " tasks failed after " << options_.retries + 1
              << " attempts; their trials count as failed (seeds above; replay one with `trimbot run SCENARIO --seed "
                 "SEED --trials 1`)"
              << std::endl;
  }
  return codes;
}

}  // namespace trimbot::scenarios
