// What every `dcm` command's flags share: the checks that refuse a bad value
// at parse time (exit 2, the flag named as typed: "--threshold: must be a
// finite number >= 0, got nan"), the help groups and their order.
//
// A value the user typed is used as typed or refused; no flag takes "0" or a
// negative number to mean "the default" (std::optional holds "not given").
#pragma once

#include <CLI/CLI.hpp>

#include <cfloat>
#include <cstdint>
#include <functional>
#include <string>

#include "dcm/status.h"

namespace dcm::cli {

/// The help groups, in the order `--help` lists them (HelpFormatter): first
/// CLI11's own (--help, -v, -q), then the command's.
inline constexpr const char* kGroupGeneral = "Options";
inline constexpr const char* kGroupIo = "Inputs and outputs";
inline constexpr const char* kGroupQuality = "Quality";
inline constexpr const char* kGroupGuides = "Guides";
inline constexpr const char* kGroupTiles = "Tiles and frames";
inline constexpr const char* kGroupNoise = "Noise";
inline constexpr const char* kGroupRounds = "Rounds";
inline constexpr const char* kGroupInternals = "Engine internals";

/// Worker threads: at most this many. TBB builds an arena of as many slots as
/// asked (10 million ended in SIGSEGV); 1024 is past every machine dcm runs
/// on, and a fixed bound keeps a job script valid from one node to the next.
inline constexpr int kMaxThreads = 1024;

/// --provider-timeout and --provider-startup-timeout: at most this many
/// seconds (11.6 days). The deadline is steady_clock::now() plus the timeout
/// in nanoseconds; 1e10 s overflowed int64 nanoseconds, 1e6 s is 1e15 ns.
inline constexpr double kMaxTimeoutSeconds = 1e6;

/// A finite number from `lo` to `hi` ("--x: must be a finite number >= 0,
/// got nan"); `above` makes the lower bound exclusive. The bound FLT_MAX keeps
/// a value finite as a float too. Apply with ->transform(): it rewrites the
/// value in the one notation CLI11 then converts (no hexadecimal surprises).
CLI::Validator FiniteNumber(double lo, double hi = FLT_MAX, bool above = false);

/// A decimal integer from `lo` to `hi` (CLI11 alone would read "010" as 8).
/// Apply with ->transform().
CLI::Validator Integer(int64_t lo, int64_t hi);

/// A power of two from `lo` to `hi`. Apply with ->transform().
CLI::Validator PowerOfTwo(int lo, int hi);

/// A value that `parse` accepts; its message becomes the flag's.
CLI::Validator Parsed(const std::string& what, std::function<Status(const std::string&)> parse);

/// "--help" with the option groups in the order of the kGroup* constants
/// (CLI11 lists them in the order of their first option, which depends on
/// which helper added its flags first), then any other group; a default
/// follows the description ("(default: 0.14)") instead of the value's type
/// and range ("FLOAT:>= 0=0.14").
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override;
  std::string make_option_opts(const CLI::Option* opt) const override;
  std::string make_option_desc(const CLI::Option* opt) const override;
};

/// The line after a usage error ("dcm render: error: --block: ..."); the
/// command is the subcommand being parsed, if any.
std::string UsageErrorMessage(const CLI::App& app, const CLI::Error& e);

/// The exit codes, for the --help footer of every command.
std::string ExitCodesHelp();

}  // namespace dcm::cli
