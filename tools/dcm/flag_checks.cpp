#include "flag_checks.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "commands.h"

namespace dcm::cli {
namespace {

/// A bound as a user writes it: 1000000, not 1e+06.
std::string Number(double v) {
  char buf[64];
  if (v == std::floor(v) && std::fabs(v) < 1e15) std::snprintf(buf, sizeof buf, "%.0f", v);
  else std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// The whole of `s` as a T (a leading '+' allowed); false on anything else.
template <typename T>
bool ParseWhole(const std::string& s, T* v) {
  const char* first = s.data();
  const char* last = s.data() + s.size();
  if (first != last && *first == '+') ++first;
  if (first == last) return false;
  const auto [end, ec] = std::from_chars(first, last, *v);
  return ec == std::errc() && end == last;
}

std::string Range(int64_t lo, int64_t hi) { return "from " + std::to_string(lo) + " to " + std::to_string(hi); }

}  // namespace

CLI::Validator FiniteNumber(double lo, double hi, bool above) {
  std::string what = "must be a finite number ";
  std::string desc;
  if (hi >= double(FLT_MAX)) {
    what += (above ? "> " : ">= ") + Number(lo);
    desc = (above ? "> " : ">= ") + Number(lo);
  } else if (above) {
    what += "> " + Number(lo) + " and <= " + Number(hi);
    desc = "> " + Number(lo) + ", <= " + Number(hi);
  } else {
    what += "from " + Number(lo) + " to " + Number(hi);
    desc = Number(lo) + " to " + Number(hi);
  }
  return CLI::Validator(
      [lo, hi, above, what](std::string& s) -> std::string {
        double v = 0;
        if (!ParseWhole(s, &v) || !std::isfinite(v) || v > hi || (above ? !(v > lo) : !(v >= lo)))
          return what + ", got " + s;
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g", v);
        s = buf;
        return {};
      },
      desc);
}

CLI::Validator Integer(int64_t lo, int64_t hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        int64_t v = 0;
        if (!ParseWhole(s, &v) || v < lo || v > hi) return "must be an integer " + Range(lo, hi) + ", got " + s;
        s = std::to_string(v);
        return {};
      },
      std::to_string(lo) + " to " + std::to_string(hi));
}

CLI::Validator PowerOfTwo(int lo, int hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        int64_t v = 0;
        if (!ParseWhole(s, &v) || v < lo || v > hi || (v & (v - 1)) != 0)
          return "must be a power of two " + Range(lo, hi) + ", got " + s;
        s = std::to_string(v);
        return {};
      },
      "power of two, " + std::to_string(lo) + " to " + std::to_string(hi));
}

CLI::Validator Parsed(const std::string& what, std::function<Status(const std::string&)> parse) {
  return CLI::Validator(
      [parse](std::string& s) -> std::string {
        const Status st = parse(s);
        return st.ok() ? std::string() : st.message();
      },
      what);
}

std::string HelpFormatter::make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const {
  if (mode == CLI::AppFormatMode::Sub) return make_expanded(app);
  std::vector<std::string> groups = {kGroupGeneral, kGroupIo,    kGroupQuality,  kGroupGuides,
                                     kGroupTiles,   kGroupNoise, kGroupRounds, kGroupInternals};
  for (const std::string& g : app->get_groups())
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
  std::ostringstream out;
  out << make_description(app) << make_usage(app, name) << make_positionals(app);
  for (const std::string& group : groups) {
    const std::vector<const CLI::Option*> opts = app->get_options([&](const CLI::Option* o) {
      return o->get_group() == group && o->nonpositional() && !group.empty();
    });
    if (!opts.empty()) out << make_group(group, false, opts);
  }
  out << make_subcommands(app, mode) << '\n' << make_footer(app);
  return out.str();
}

std::string HelpFormatter::make_option_opts(const CLI::Option* opt) const {
  std::string out;
  if (opt->get_type_size() != 0) {
    if (!opt->get_type_name().empty()) out += " " + get_label(opt->get_type_name());
    if (opt->get_expected_max() == CLI::detail::expected_max_vector_size) out += " ...";
    if (opt->get_required()) out += " " + get_label("REQUIRED");
  }
  if (!opt->get_excludes().empty()) {
    out += " " + get_label("Excludes") + ":";
    for (const CLI::Option* o : opt->get_excludes()) out += " " + o->get_name();
  }
  return out;
}

std::string HelpFormatter::make_option_desc(const CLI::Option* opt) const {
  std::string desc = opt->get_description();
  if (opt->get_type_size() != 0 && !opt->get_default_str().empty())
    desc += " (default: " + opt->get_default_str() + ")";
  return desc;
}

std::string UsageErrorMessage(const CLI::App& app, const CLI::Error& e) {
  std::string cmd = "dcm";
  const auto subs = app.get_subcommands();
  if (!subs.empty()) cmd += " " + subs.front()->get_name();
  return cmd + ": error: " + e.what() + "\nRun `" + cmd + " --help` for the flags.\n";
}

std::string ExitCodesHelp() {
  return "Exit codes: " + std::to_string(kExitOk) + " done; " + std::to_string(kExitFailure) +
         " failed (bad input, provider or write error); " + std::to_string(kExitUsage) +
         " bad command line (the flag is named); 128+N ended by signal N.";
}

}  // namespace dcm::cli
