#pragma once
// Every executable's command line parsed one way (docs/sessions.md "Exit
// codes"): --help and --version print and exit 0; a usage error (an unknown
// option, a missing or bad argument) prints CLI11's message with a pointer
// to --help and exits 2.
#include <CLI/CLI.hpp>
#include <optional>

namespace rms {

inline constexpr int kUsageExitCode = 2;

// The exit code when the program must stop here, or nullopt to go on.
inline std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kUsageExitCode;
  }
  return std::nullopt;
}

}  // namespace rms
