// SPDX-License-Identifier: MIT
// dynaqpc-sim: a small declarative option parser shared by the subcommands.
#ifndef DYNAQPC_SIM_OPTIONS_H
#define DYNAQPC_SIM_OPTIONS_H

#include <cstdint>
#include <cstdio>
#include <functional>
#include <iosfwd>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace dynaqpc {

/// Exit statuses of dynaqpc-sim: 0 success, 1 a failure while running (I/O), 2 bad usage or bad
/// input (an option, a map).
enum ExitStatus { kExitOk = 0, kExitFailure = 1, kExitUsage = 2 };

/// A bad command line or bad input. what() is the one line printed on stderr (without the
/// program-name prefix).
class UsageError : public std::runtime_error {
public:
    explicit UsageError(const std::string &msg) : std::runtime_error(msg) {}
};

/// Options of one subcommand: `--name VALUE`, `--name=VALUE` or a `--flag`. Each option writes
/// its parsed value into a caller's variable; numbers are checked whole (no trailing junk),
/// finite and in range. Given twice, unknown, or missing its value: UsageError naming it.
///
///     Options opts("maze", "run a gridworld experiment");
///     opts.add_uint("--runs", "R", "independent runs", &runs, 1, 1000000);
///     opts.parse(args);                   // throws UsageError
///     if (opts.seen("--episodes")) ...
class Options {
public:
    Options(std::string command, std::string summary);

    void add_flag(const std::string &name, const std::string &help, bool *target);
    void add_string(const std::string &name, const std::string &metavar, const std::string &help,
                    std::string *target);
    void add_uint(const std::string &name, const std::string &metavar, const std::string &help,
                  std::uint32_t *target, std::uint32_t min, std::uint32_t max);
    /// min_open / max_open exclude the bound itself (alpha in (0, 1]).
    void add_double(const std::string &name, const std::string &metavar, const std::string &help,
                    double *target, double min, double max, bool min_open = false,
                    bool max_open = false);
    /// One of a fixed set of words.
    void add_choice(const std::string &name, const std::string &metavar, const std::string &help,
                    std::string *target, std::vector<std::string> choices);

    /// Parses the arguments after the subcommand. `--help`/`-h` stops it (parse_or_usage()).
    void parse(const std::vector<std::string> &args);

    /// What every command does first: parse(), and when `--help`/`-h` was given, print_usage() to
    /// standard output under `program`'s name. True then: the command adds any help of its own
    /// and returns kExitOk, doing nothing else.
    bool parse_or_usage(const std::vector<std::string> &args, const std::string &program);
    bool seen(const std::string &name) const { return seen_.count(name) != 0; }
    /// A command's required option: unless it was given, UsageError "<name>: required (<what>)"
    /// ("<name>: required" when `what` is empty).
    void require(const std::string &name, const std::string &what = "") const;

    /// "Usage: ..." and one line per option.
    void print_usage(std::ostream &out, const std::string &program) const;

private:
    struct Spec {
        std::string name;
        std::string metavar;  // empty: a flag
        std::string help;
        std::function<void(const std::string &)> apply;
    };
    void add(Spec spec);
    const Spec *find(const std::string &name) const;

    std::string command_;
    std::string summary_;
    std::vector<Spec> specs_;
    std::set<std::string> seen_;
    bool help_ = false;
};

/// A command's main, for a command whose settings are one struct: a `Settings` declared as the
/// options of `command` by `declare`, then parsed from `args` (parse_or_usage()). With `--help`:
/// the usage, then `help` (the command's own, if any), and kExitOk. Else `run`, given the options
/// (which were given: seen()) and the settings they set: the status it returns, or kExitOk when
/// it returns nothing (it fails by throwing).
template <typename Settings, typename Result>
int run_command(const std::string &program, const std::vector<std::string> &args,
                const std::string &command, const std::string &summary,
                void (*declare)(Options &, Settings &),
                Result (*run)(const std::string &program, const Options &o, Settings &s),
                void (*help)() = nullptr)
{
    Settings s;
    Options o(command, summary);
    declare(o, s);
    if (o.parse_or_usage(args, program)) {
        if (help != nullptr) {
            help();
        }
        return kExitOk;
    }
    if constexpr (std::is_void_v<Result>) {
        run(program, o, s);
        return kExitOk;
    } else {
        return run(program, o, s);
    }
}

/// Strict number parsing, for options and for other callers; `what` names the option in errors.
std::uint32_t parse_uint(const std::string &what, const std::string &text, std::uint32_t min,
                         std::uint32_t max);
double parse_double(const std::string &what, const std::string &text, double min, double max,
                    bool min_open = false, bool max_open = false);

/// Opens the file an output option (`--csv`) names, for writing: standard output for "-". When it
/// cannot: UsageError "<option>: cannot open '<path>': <reason>".
std::FILE *open_output(const std::string &option, const std::string &path);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_OPTIONS_H
