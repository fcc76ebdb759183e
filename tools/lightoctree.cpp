// lightoctree: the command-line front end. Parses, calls the stages, reports.

#include <fcntl.h>
#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <system_error>

#include "cli_checks.h"
#include "commands.h"
#include "core/file.h"
#include "core/printable.h"
#include "core/resources.h"
#include "distributed/mpi_session.h"
#include "distributed/rank_agreement.h"

namespace {

/// Exit status of a command line the parser refuses (docs: README, "Exit status").
constexpr int kUsageError = 2;

/// The command being run ("bake"), for the messages of the last resort.
std::string commandName;

std::string program() { return commandName.empty() ? "lightoctree" : "lightoctree " + commandName; }

/// What to lower when `command` ran out of memory.
std::string memoryAdvice() {
  if (commandName == "bake") {
    return "use a smaller --depth, fewer --photons or --max-photons, or only the part that "
           "matters (--bounds)";
  }
  if (commandName == "convert") return "use a smaller --depth";
  if (commandName == "lightmap") return "use a larger --texel-size or a smaller --atlas";
  if (commandName == "render" || commandName == "reference" || commandName == "view") {
    return "use a smaller --width and --height, or a smaller scene";
  }
  if (commandName == "sweep") return "sweep smaller depths and photon counts";
  return "give the process more memory";
}

/// The allocation failure main's catch and terminateSaysMemory report.
void sayOutOfMemory() {
  std::string advice;
  try {
    advice = memoryAdvice();
  } catch (...) {
    advice = "give the process more memory";
  }
  std::fprintf(stderr,
               "%s: error: out of memory (an allocation failed): the machine or the "
               "process's limits (ulimit -v, the container's, LIGHTOCTREE_MEMORY_LIMIT) "
               "hold less than this run needs: %s\n",
               program().c_str(), advice.c_str());
}

/// A thread that could not start, for want of address space: TBB says
/// "pthread_create has failed" in a std::runtime_error.
bool isThreadStartFailure(const std::exception& e) {
  if (const auto* error = dynamic_cast<const std::system_error*>(&e)) {
    return error->code() == std::errc::resource_unavailable_try_again;
  }
  return std::strstr(e.what(), "pthread_create") != nullptr;
}

/// A thread that could not start: said as the limits it meets (H16-2-2:
/// under `ulimit -u` it was called out of memory, or "terminate called").
void sayThreadsShort() {
  std::fprintf(stderr,
               "lightoctree: error: cannot start a thread: out of memory for its stack "
               "(ulimit -v, the container's memory) or at the limit on this user's processes "
               "and threads (ulimit -u, a container's pids limit): raise the limit reached, or "
               "run fewer processes beside this one\n");
}

std::terminate_handler defaultTerminate = nullptr;

/// The last resort past main's catch: an allocation or a thread start that
/// failed where no catch can take it ends here, not in "terminate called
/// after throwing": OpenVDB frees a tree with TBB (allocating, starting
/// threads) while a read that ran out of memory unwinds, and a throw from
/// that destructor ends the process (H12-2-68, `ulimit -v`). Temporary files
/// are removed, the shortage said, exit status 1. Anything else goes to the
/// runtime's own handler.
[[noreturn]] void terminateSaysMemory() {
  bool memory = false, thread = false;
  if (const std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      memory = true;
    } catch (const std::exception& error) {
      thread = isThreadStartFailure(error);
    } catch (...) {
    }
  }
  if (memory || thread) {
    lo::removeLiveTemporaries();
    if (memory) {
      sayOutOfMemory();
    } else {
      sayThreadsShort();
    }
    std::fflush(stderr);
    ::_exit(1);
  }
  if (defaultTerminate) defaultTerminate();
  std::abort();
}

/// A closed standard stream (a script's `>&-`) would be taken by the next file
/// opened, and a report printed into a `.vdb`. Each one closed gets /dev/null
/// opened for reading: nothing else can take it, and a write to it fails
/// (EBADF) as it would on the closed stream, which finishOutput reports.
void holdClosedStandardStreams() {
  for (int fd = 0; fd <= 2; ++fd) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    const int held = ::open("/dev/null", O_RDONLY);
    if (held >= 0 && held != fd) {
      ::dup2(held, fd);
      ::close(held);
    }
  }
}

/// A report that did not reach standard output (a full disk, /dev/full, a
/// closed stream) is a failure: a script reading it would get nothing, or
/// half, with exit status 0. @returns `rc`, or 1 with a message.
int finishOutput(int rc) {
  std::cout.flush();
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  const int error = errno;
  if (flushed && !std::ferror(stdout) && !std::cout.fail()) return rc;
  std::fprintf(stderr, "%s: error: cannot write to standard output%s%s: the report is lost\n",
               program().c_str(), error ? ": " : "", error ? std::strerror(error) : "");
  return rc == 0 ? 1 : rc;
}

/// Stops the process when its resident memory grows past
/// LIGHTOCTREE_MEMORY_LIMIT: the estimates checked before the work (photons,
/// voxels, pages) do not see everything that grows. Runs on the watch's
/// thread, so it removes the temporary outputs itself and ends at once.
void onMemoryLimit(size_t rss, size_t limit) {
  std::fprintf(stderr,
               "%s: error: out of memory: the process grew to %s, past "
               "LIGHTOCTREE_MEMORY_LIMIT=%s (%s); stopped, nothing written: %s\n",
               program().c_str(), lo::formatBytes(rss).c_str(),
               std::getenv("LIGHTOCTREE_MEMORY_LIMIT"), lo::formatBytes(limit).c_str(),
               memoryAdvice().c_str());
  lo::removeLiveTemporaries();
  std::fflush(stderr);
  std::_Exit(1);
}

/// "--photons: '1e5' is not a whole number in digits (100000, not 1e5): see
/// `lightoctree bake --help`" for the parser's "Could not convert: --photons
/// = 1e5"; its own text where it is not of that form.
std::string conversionMessage(const CLI::App& app, const std::string& parserText) {
  const std::string prefix = "Could not convert: ";
  const size_t equals = parserText.find(" = ");
  if (parserText.rfind(prefix, 0) != 0 || equals == std::string::npos) return parserText;
  const std::string flag = parserText.substr(prefix.size(), equals - prefix.size());
  const std::string value = parserText.substr(equals + 3);
  std::string kind = "a number", command = "lightoctree";
  for (const CLI::App* sub : app.get_subcommands()) {
    command = "lightoctree " + sub->get_name();
    for (const CLI::Option* option : sub->get_options()) {
      if (!option->check_name(flag)) continue;
      const std::string type = option->get_type_name();
      if (type.find("INT") != std::string::npos) {
        kind = "a whole number in digits (100000, not 1e5 or 1.0)";
      }
    }
  }
  return flag + ": '" + value + "' is not " + kind + ": see `" + command + " --help`";
}

/// Under mpirun beside other ranks (an MPI build), a rank that bakes nothing
/// (--version, --help, inspect) ends the job with the bake ranks, which
/// would wait for it in MPI_Init forever: every rank refuses, rank 0 says
/// why. Else `rc` (also where MPI finds the process alone: a size variable
/// left in a job script's environment).
int leaveBakeRanks(int argc, char** argv, int rc) {
  if (lo::mpiLaunchSize() < 2 || !lo::mpiAvailable()) return rc;
  std::string given;
  for (int i = 1; i < argc && i < 4; ++i) given += (i > 1 ? " " : "") + std::string(argv[i]);
  std::string message;
  if (!lo::refuseBakeRanks(given, message)) return rc;
  if (!message.empty()) {
    std::fprintf(stderr, "lightoctree: error: %s\n", lo::printable(message).c_str());
  }
  return 1;
}

int run(int argc, char** argv) {
  CLI::App app{
      "Light Octree " LO_VERSION
      ": bakes photon-mapped global illumination into sparse OpenVDB grids of virtual "
      "directional lights.",
      "lightoctree"};
  app.require_subcommand(1);
  app.set_version_flag("--version", LO_VERSION);
  std::vector<std::function<int()>> commands;
  commands.push_back(lo::tool::addBakeCommand(app));
  commands.push_back(lo::tool::addRenderCommand(app));
  commands.push_back(lo::tool::addLightmapCommand(app));
  commands.push_back(lo::tool::addConvertCommand(app));
  commands.push_back(lo::tool::addInspectCommand(app));
  commands.push_back(lo::tool::addReferenceCommand(app));
  commands.push_back(lo::tool::addCompareCommand(app));
  commands.push_back(lo::tool::addSweepCommand(app));
  commands.push_back(lo::tool::addViewCommand(app));
  lo::tool::requireNumberRules(app);  // every numeric flag, those with a range or not
  // The parser's own messages ("scene: File does not exist: NAME") quote what
  // was typed: escaped as every other error, where a name's newline and
  // terminal escapes reached the terminal raw.
  app.failure_message([](const CLI::App* from, const CLI::Error& e) {
    std::string text = lo::printable(e.what()) + "\n";
    if (from->get_help_ptr() != nullptr) {
      text += "Run with " + from->get_help_ptr()->get_name() + " for more information.\n";
    }
    return text;
  });
  try {
    app.parse(argc, argv);
  } catch (const CLI::ConversionError& e) {
    // The parser's "Could not convert: --photons = 1e5" says neither what
    // the flag takes nor how to write it.
    std::fprintf(stderr, "lightoctree: error: %s\n", conversionMessage(app, e.what()).c_str());
    return kUsageError;
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a usage error exits 2, as command-line
    // tools do (the parser's own codes, 105-109, say nothing to a script).
    return app.exit(e) == 0 ? leaveBakeRanks(argc, argv, 0) : kUsageError;
  }
  for (const CLI::App* sub : app.get_subcommands()) commandName = sub->get_name();
  if (commandName != "bake") {
    const int rc = leaveBakeRanks(argc, argv, -1);
    if (rc >= 0) return rc;
  }
  const size_t limit = lo::memoryLimitSetting();
  const lo::MemoryWatch watch(limit, [limit](size_t rss) { onMemoryLimit(rss, limit); });
  for (auto& command : commands) {
    int rc = command();
    if (rc >= 0) return rc;
  }
  return 1;
}

/// The handler set before the shared libraries' own initialisers run:
/// log4cplus (OpenVDB's logger) starts its thread pool there, and under a
/// tight `ulimit -u` that start failed before main set anything (H16-2-2).
void setTerminateHandler(int, char**, char**) {
  defaultTerminate = std::set_terminate(terminateSaysMemory);
}
__attribute__((section(".preinit_array"),
               used)) void (*const setTerminateFirst)(int, char**, char**) = setTerminateHandler;

/// The stack a command needs: the software GL driver's shader compiler
/// (LLVM) and the libraries' recursions were written for the usual 8 MiB.
constexpr size_t kStackBytes = size_t(8) << 20;

/// Whether the main thread's stack may grow to kStackBytes, its soft limit
/// raised that far if the hard one allows. Else (`ulimit -s 128` sets both;
/// `lightmap` crashed, H16-2-3) the command runs on a thread of that stack,
/// which the limit does not hold; and every thread the process starts gets
/// that stack, not the limit's (glibc's default follows `ulimit -s`).
bool mainStackHolds() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_STACK, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY ||
      limit.rlim_cur >= kStackBytes) {
    return true;
  }
  pthread_attr_t attributes;
  if (::pthread_attr_init(&attributes) == 0) {
    ::pthread_attr_setstacksize(&attributes, kStackBytes);
    ::pthread_setattr_default_np(&attributes);
    ::pthread_attr_destroy(&attributes);
  }
  if (limit.rlim_max != RLIM_INFINITY && limit.rlim_max < kStackBytes) return false;
  limit.rlim_cur = kStackBytes;
  return ::setrlimit(RLIMIT_STACK, &limit) == 0;
}

int runAndReport(int argc, char** argv) {
  try {
    return finishOutput(run(argc, argv));
  } catch (const std::bad_alloc&) {
    // The checks before the work compare estimates with the memory available
    // (the machine's, the cgroup's, ulimit -v, LIGHTOCTREE_MEMORY_LIMIT);
    // what they missed ends here, said plainly.
    sayOutOfMemory();
    finishOutput(1);
    return 1;
  } catch (const std::exception& e) {
    if (isThreadStartFailure(e)) {
      sayThreadsShort();
      finishOutput(1);
      return 1;
    }
    // A message may quote what a file holds (a grid's name in OpenVDB's
    // error, a scene's name): its control characters escaped, its lines kept.
    std::fprintf(stderr, "lightoctree: error: %s\n", lo::printable(e.what(), true).c_str());
    finishOutput(1);
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  holdClosedStandardStreams();
  // Past the file-size limit (ulimit -f) a write fails with EFBIG, reported
  // as any failed write with its temporary file removed, instead of the
  // signal ending the process and leaving the temporary behind.
  std::signal(SIGXFSZ, SIG_IGN);
  if (mainStackHolds()) return runAndReport(argc, argv);
  struct Call {
    int argc;
    char** argv;
    int rc;
  } call{argc, argv, 1};
  pthread_attr_t attributes;
  pthread_t thread;
  const bool started = ::pthread_attr_init(&attributes) == 0 &&
                       ::pthread_attr_setstacksize(&attributes, kStackBytes) == 0 &&
                       ::pthread_create(
                           &thread, &attributes,
                           [](void* p) -> void* {
                             auto* c = static_cast<Call*>(p);
                             c->rc = runAndReport(c->argc, c->argv);
                             return nullptr;
                           },
                           &call) == 0;
  if (!started) {
    sayThreadsShort();
    return 1;
  }
  ::pthread_join(thread, nullptr);
  return call.rc;
}
