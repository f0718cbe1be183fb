#include "cli/commands.h"

#include "polycube/errors.h"
#include "polycube/parallel.h"

#include <cstdio>
#include <iomanip>
#include <iostream>
#include <new>
#include <sstream>

namespace polycube::cli {

void Progress::stage(const std::string& name, const std::string& message) const {
  if (options_.quiet) return;
  std::cerr << "[" << std::fixed << std::setprecision(2) << std::setw(7) << elapsed_seconds() << " s] " << name;
  if (!message.empty()) std::cerr << ": " << message;
  std::cerr << std::endl;
}

void Progress::warning(const std::string& message) const {
  if (options_.quiet) return;
  std::cerr << "warning: " << message << std::endl;
}

double Progress::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool TimeLimit::over(const Progress& progress) const { return seconds > 0 && progress.elapsed_seconds() >= seconds; }

bool TimeLimit::spent(const Progress& progress) {
  if (over(progress)) reached = true;
  return reached;
}

void TimeLimit::warn(const Progress& progress, const std::string& what) const {
  if (!reached) return;
  std::ostringstream text;
  text << "--time-limit " << seconds << " s reached: no further try started (" << what << "); the best so far is written";
  progress.warning(text.str());
}

std::function<bool()> TimeLimit::stop_for(const Progress& progress) const {
  if (seconds <= 0) return {};
  return [&progress, limit = *this]() { return limit.over(progress); };
}

void add_time_limit_option(CLI::App& command, TimeLimit& limit) {
  command
      .add_option("--time-limit", limit.seconds,
                  "Seconds after which no further try starts (other orientations, finer contours, thin parts, exact "
                  "sampling); the try under way finishes and the best so far is written, with a warning; 0: no limit")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
}

namespace {

int fail(ExitCode code, const std::string& message) {
  std::cerr << "polycube: error: " << message << std::endl;
  return code;
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"polycube: automatic polycube maps for closed surfaces of any genus"};
  app.set_version_flag("--version", "polycube 0.1.0");
  app.require_subcommand(1);
  app.fallthrough();  // global options also after the subcommand: `polycube inspect m.obj --quiet`
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No progress or warnings on stderr");
  app.add_option("--threads", global.threads,
                 "Most threads each parallel step uses (0: one per hardware thread); the results do not depend on it")
      ->check(CLI::Range(0, 1024));
  CommandRunner runner;
  add_inspect_command(app, global, runner);
  add_map_command(app, global, runner);
  add_quad_command(app, global, runner);

  // CLI11 would say "A subcommand is required" for a mistyped command; name it instead.
  if (argc > 1 && argv[1][0] != '-' && app.get_subcommands([&](const CLI::App* c) { return c->get_name() == argv[1]; }).empty())
    return fail(kUsageError, std::string("unknown command '") + argv[1] + "' (see polycube --help)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail(kUsageError, std::string(e.what()) + " (see polycube --help)");
  }

  thread_limit() = global.threads;
  try {
    return runner();
  } catch (const InputError& e) {
    return fail(kInputError, e.what());
  } catch (const MeshError& e) {
    return fail(kMeshError, e.what());
  } catch (const OutputError& e) {
    return fail(kOutputError, e.what());
  } catch (const AlgorithmError& e) {
    return fail(kAlgorithmError, e.what());
  } catch (const std::bad_alloc&) {
    return fail(kInternalError, "out of memory");
  } catch (const std::exception& e) {
    return fail(kInternalError, std::string("internal error: ") + e.what());
  }
}

}  // namespace polycube::cli
