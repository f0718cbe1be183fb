// The `polycube` command line. cli/ is the only place that prints and picks exit codes; the
// engine and formats libraries throw (polycube/errors.h) and report progress through callbacks.
#pragma once

#include <CLI/CLI.hpp>

#include <chrono>
#include <functional>
#include <string>

namespace polycube::cli {

// Exit codes, documented in README.md.
enum ExitCode : int {
  kSuccess = 0,
  kInternalError = 1,    // a bug or an exhausted resource: please report
  kUsageError = 2,       // bad command line
  kInputError = 3,       // the input file cannot be read or parsed
  kMeshError = 4,        // the mesh was read but cannot be mapped (open, non-manifold, ...)
  kOutputError = 5,      // an output cannot be written
  kAlgorithmError = 6,   // a stage could not produce a valid result within its limits
};

// Options every subcommand shares.
struct GlobalOptions {
  bool quiet = false;
  int threads = 0;  // most threads per parallel step (0: one per hardware thread)
};

// Stage progress on stderr: "[  1.23 s] stage: message". Silent with --quiet.
class Progress {
 public:
  explicit Progress(const GlobalOptions& options) : options_(options), start_(std::chrono::steady_clock::now()) {}
  void stage(const std::string& name, const std::string& message = "") const;
  void warning(const std::string& message) const;
  double elapsed_seconds() const;

 private:
  const GlobalOptions& options_;
  std::chrono::steady_clock::time_point start_;
};

// --time-limit of `map` and `quad`: once a command has a result, it starts no further try
// (another orientation, finer contours, thin parts, an exact sampling) after this many seconds
// from its start; the try under way finishes and the best so far is written. 0: no limit.
struct TimeLimit {
  double seconds = 0;
  bool reached = false;  // a try was left out for it
  // True, and `reached` set, when the limit is set and spent: the caller starts no further try.
  bool spent(const Progress& progress);
  // Whether the limit is set and spent (reached is not touched).
  bool over(const Progress& progress) const;
  // "--time-limit S s reached: no further try started (<what>); ..." as a warning, when reached.
  void warn(const Progress& progress, const std::string& what) const;
  // For a search the command can do without (it already has a result): true once the limit is
  // spent, safe to call from any thread (AlignmentOptions::stop); empty without a limit. The
  // caller then calls spent() to set `reached`.
  std::function<bool()> stop_for(const Progress& progress) const;
};
void add_time_limit_option(CLI::App& command, TimeLimit& limit);

// Each subcommand registers itself on the app and sets the callback that runs it.
// The callback returns the exit code; exceptions are mapped to exit codes by run().
using CommandRunner = std::function<int()>;
void add_inspect_command(CLI::App& app, const GlobalOptions& global, CommandRunner& runner);
void add_map_command(CLI::App& app, const GlobalOptions& global, CommandRunner& runner);
void add_quad_command(CLI::App& app, const GlobalOptions& global, CommandRunner& runner);

// Parses argv, runs the chosen subcommand, prints one-line errors, returns the exit code.
int run(int argc, char** argv);

}  // namespace polycube::cli
