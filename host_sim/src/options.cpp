// SPDX-License-Identifier: MIT
// dynaqpc-sim: option parsing shared by the subcommands.
#include "options.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <ostream>
#include <utility>

namespace dynaqpc {

namespace {

std::string format_number(double x)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", x);
    return buf;
}

// A user's text as it may appear in a one-line message: control characters escaped.
std::string printable(const std::string &text)
{
    std::string out;
    for (unsigned char c : text) {
        if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
        } else {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", c);
            out += buf;
        }
    }
    return out;
}

std::string quoted(const std::string &text)
{
    return "'" + printable(text) + "'";
}

}  // namespace

std::uint32_t parse_uint(const std::string &what, const std::string &text, std::uint32_t min,
                         std::uint32_t max)
{
    const std::string range = " from " + std::to_string(min) + " to " + std::to_string(max);
    if (text.size() > 1 && text[0] == '-' && text.find_first_not_of("0123456789", 1) == std::string::npos) {
        throw UsageError(what + ": " + quoted(text) + " is negative; it takes a whole number" + range);
    }
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) {
        throw UsageError(what + ": expected a whole number" + range + ", got " + quoted(text));
    }
    errno = 0;
    const unsigned long long v = std::strtoull(text.c_str(), nullptr, 10);
    if (errno == ERANGE || v < min || v > max) {
        throw UsageError(what + ": " + quoted(text) + " is out of range [" + std::to_string(min) +
                         ", " + std::to_string(max) + "]");
    }
    return static_cast<std::uint32_t>(v);
}

double parse_double(const std::string &what, const std::string &text, double min, double max,
                    bool min_open, bool max_open)
{
    // strtod would skip leading spaces and accept "inf", "nan" and hex: refuse what a person
    // would not mean as a setting.
    if (text.empty() ||
        text.find_first_not_of("0123456789+-.eE") != std::string::npos) {
        throw UsageError(what + ": expected a number, got " + quoted(text));
    }
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0') {
        throw UsageError(what + ": expected a number, got " + quoted(text));
    }
    if (errno == ERANGE || !std::isfinite(v) || v < min || v > max || (min_open && v == min) ||
        (max_open && v == max)) {
        throw UsageError(what + ": " + quoted(text) + " is out of range " + (min_open ? "(" : "[") +
                         format_number(min) + ", " + format_number(max) + (max_open ? ")" : "]"));
    }
    return v;
}

Options::Options(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary))
{
}

void Options::add(Spec spec)
{
    specs_.push_back(std::move(spec));
}

const Options::Spec *Options::find(const std::string &name) const
{
    for (const Spec &s : specs_) {
        if (s.name == name) {
            return &s;
        }
    }
    return nullptr;
}

void Options::add_flag(const std::string &name, const std::string &help, bool *target)
{
    add({name, "", help, [target](const std::string &) { *target = true; }});
}

void Options::add_string(const std::string &name, const std::string &metavar,
                         const std::string &help, std::string *target)
{
    add({name, metavar, help, [name, target](const std::string &v) {
             if (v.empty()) {
                 throw UsageError(name + ": empty value");
             }
             *target = v;
         }});
}

void Options::add_uint(const std::string &name, const std::string &metavar,
                       const std::string &help, std::uint32_t *target, std::uint32_t min,
                       std::uint32_t max)
{
    add({name, metavar, help, [name, target, min, max](const std::string &v) {
             *target = parse_uint(name, v, min, max);
         }});
}

void Options::add_double(const std::string &name, const std::string &metavar,
                         const std::string &help, double *target, double min, double max,
                         bool min_open, bool max_open)
{
    add({name, metavar, help, [=](const std::string &v) {
             *target = parse_double(name, v, min, max, min_open, max_open);
         }});
}

void Options::add_choice(const std::string &name, const std::string &metavar,
                         const std::string &help, std::string *target,
                         std::vector<std::string> choices)
{
    add({name, metavar, help, [name, target, choices](const std::string &v) {
             std::string list;
             for (const std::string &c : choices) {
                 if (c == v) {
                     *target = v;
                     return;
                 }
                 list += (list.empty() ? "" : ", ") + c;
             }
             throw UsageError(name + ": unknown value " + quoted(v) + " (expected one of " +
                              list + ")");
         }});
}

void Options::parse(const std::vector<std::string> &args)
{
    for (std::size_t i = 0; i < args.size(); i++) {
        const std::string &arg = args[i];
        if (arg == "--help" || arg == "-h") {
            help_ = true;
            return;
        }
        if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) {
            throw UsageError("unexpected argument " + quoted(arg) + " (options start with --)");
        }
        const std::size_t eq = arg.find('=');
        const std::string name = arg.substr(0, eq);
        const Spec *spec = find(name);
        if (spec == nullptr) {
            throw UsageError(printable(name) + ": unknown option");
        }
        if (seen_.count(name) != 0) {
            throw UsageError(name + ": given more than once");
        }
        seen_.insert(name);
        if (spec->metavar.empty()) {
            if (eq != std::string::npos) {
                throw UsageError(name + ": takes no value");
            }
            spec->apply("");
            continue;
        }
        if (eq != std::string::npos) {
            spec->apply(arg.substr(eq + 1));
        } else if (i + 1 < args.size()) {
            // A value may start with '-' (a negative reward, "--csv -"), but not with "--".
            const std::string &next = args[i + 1];
            if (next.size() > 2 && next.compare(0, 2, "--") == 0) {
                throw UsageError(name + ": missing value " + spec->metavar);
            }
            spec->apply(next);
            i++;
        } else {
            throw UsageError(name + ": missing value " + spec->metavar);
        }
    }
}

// One place for the commands' shared opening, so that `--help` prints the same way for all.
bool Options::parse_or_usage(const std::vector<std::string> &args, const std::string &program)
{
    parse(args);
    if (help_) {
        print_usage(std::cout, program);
    }
    return help_;
}

void Options::require(const std::string &name, const std::string &what) const
{
    if (!seen(name)) {
        throw UsageError(name + ": required" + (what.empty() ? "" : " (" + what + ")"));
    }
}

void Options::print_usage(std::ostream &out, const std::string &program) const
{
    out << "Usage: " << program << ' ' << command_ << " [options]\n" << summary_ << "\n\nOptions:\n";
    std::vector<std::pair<std::string, std::string>> rows;
    std::size_t width = 0;
    for (const Spec &s : specs_) {
        rows.emplace_back(s.name + (s.metavar.empty() ? "" : " " + s.metavar), s.help);
        width = std::max(width, rows.back().first.size());
    }
    rows.emplace_back("--help", "print this help and exit");
    // Help text wrapped to 100 columns, continuation lines under the text.
    const std::size_t indent = 2 + width + 2;
    const std::size_t text_width = indent < 60 ? 100 - indent : 40;
    for (const auto &row : rows) {
        out << "  " << row.first << std::string(width + 2 - row.first.size(), ' ');
        std::size_t col = 0;
        std::size_t i = 0;
        const std::string &help = row.second;
        while (i < help.size()) {
            const std::size_t end = std::min(help.find(' ', i), help.size());
            const std::string word = help.substr(i, end - i);
            if (col != 0 && col + 1 + word.size() > text_width) {
                out << '\n' << std::string(indent, ' ');
                col = 0;
            } else if (col != 0) {
                out << ' ';
                col++;
            }
            out << word;
            col += word.size();
            i = end + 1;
        }
        out << '\n';
    }
}

// The commands' outputs ("-" for stdout, errors naming the option) open one way, here.
std::FILE *open_output(const std::string &option, const std::string &path)
{
    std::FILE *f = path == "-" ? stdout : std::fopen(path.c_str(), "w");
    if (f == nullptr) throw UsageError(option + ": cannot open '" + path + "': " + std::strerror(errno));
    return f;
}

}  // namespace dynaqpc
