// `repose`: the command-line face of the module, for scripts and batches. Every subcommand has
// --help, writes JSON with --json, and fails with one line on stderr and a non-zero exit.
#include "ArgParser.h"
#include "Commands.h"
#include "StderrLine.h"

#include "repose/util/Error.h"
#include "repose/util/Interrupt.h"

#include <csignal>

#include <algorithm>
#include <cstring>
#include <iostream>
#include <new>

namespace {

void printUsage() {
  std::cout << "usage: repose <command> [options]   (repose <command> --help for details)\n\n"
               "Re-poses segmented whole-body volumes with a cage.\n\ncommands:\n";
  std::size_t width = 0;
  for (const auto& c : repose::cli::kCommands) width = std::max(width, std::strlen(c.name));
  for (const auto& c : repose::cli::kCommands)
    std::cout << "  " << c.name << std::string(width + 2 - std::strlen(c.name), ' ') << c.summary
              << "\n";
}

// SIGINT / SIGTERM: ask Core to stop at its next progress point; the command then unwinds like a
// cancellation (temporary outputs removed) and exits 128 + the signal. The handler is one-shot:
// a second signal kills at once (the default action), for a user who cannot wait.
void onSignal(int signal) {
  repose::requestInterrupt(signal);
}

void installSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    printUsage();
    return argc < 2 ? 2 : 0;
  }
  if (std::strcmp(argv[1], "--version") == 0) {
    std::cout << "repose " << REPOSE_VERSION << "\n";
    return 0;
  }
  installSignalHandlers();
  const std::string name = argv[1];
  const repose::cli::Args args(argv + 2, argv + argc);
  for (const auto& command : repose::cli::kCommands) {
    if (name != command.name) continue;
    try {
      return command.run(args);
    } catch (const repose::cli::QuietExit& e) {
      return e.code;  // a rank of `warp --mpi` whose failure rank 0 reports
    } catch (const repose::cli::UsageError& e) {
      repose::cli::stderrLine("repose " + name + ": " + e.message + " (see repose " + name +
                              " --help)");
      return 2;
    } catch (const repose::Cancelled&) {
      const int signal = repose::interruptSignal();
      repose::cli::stderrLine("repose " + name + ": " +
                              (signal == SIGTERM ? "terminated" : "interrupted") +
                              "; no partial file was left");
      return 128 + (signal > 0 ? signal : SIGINT);
    } catch (const std::bad_alloc&) {
      repose::cli::stderrLine("repose " + name + ": error: out of memory");
      return 1;
    } catch (const std::exception& e) {
      repose::cli::stderrLine("repose " + name + ": error: " + e.what());
      return 1;
    }
  }
  repose::cli::stderrLine("repose: unknown command '" + name + "' (see repose --help)");
  return 2;
}
