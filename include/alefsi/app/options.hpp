#pragma once
/// \file app/options.hpp
/// A small command-line parser for programs built on alefsi (the examples and benchmarks): every
/// option is declared once, bound to a variable that holds its default, with a help text;
/// `--help` lists them all with their defaults, `print` echoes the values a run used (so a log
/// says how it was made). As MFEM's OptionsParser, in C++20.
///
///   - `--name value` (or `--name=value`) for numbers, strings, paths and lists
///     (`std::vector<std::string>`, `std::vector<double>`, ...: comma-separated);
///   - `--name` alone for a flag (bool set to true); `--no-name` sets it to false;
///   - positional arguments (e.g. a mode) are declared with `positional`.
/// A bad value or an unknown option throws InvalidArgument naming the option; `parse` returns
/// false after printing the help for `--help` (the program then exits with 0).
///
///     Real dt = 1e-3;  bool newton = false;
///     Options opt("dkt", "drafting, kissing and tumbling of two disks");
///     opt.add("dt", dt, "time step (s)").flag("newton", newton, "Newton instead of semi-implicit");
///     if (!opt.parse(argc, argv)) return 0;
///     opt.print(std::cout);
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "alefsi/core/error.hpp"

namespace alefsi {

namespace detail {
template <class T>
inline constexpr bool is_option_list = false;
template <class T>
inline constexpr bool is_option_list<std::vector<T>> = true;
}  // namespace detail

class Options {
 public:
  Options(std::string program, std::string summary) : program_(std::move(program)), summary_(std::move(summary)) {}

  /// `--name value`: `value` holds the default and receives the parsed value. T: int, long,
  /// double, std::string, std::filesystem::path or a std::vector of these (comma-separated).
  template <class T>
  Options& add(const std::string& name, T& value, const std::string& help) {
    Entry e{name, help, false, [&value] { return show(value); }, {}};
    e.set = [&value, name](const std::string& text) { value = convert<T>(name, text); };
    entries_.push_back(std::move(e));
    return *this;
  }
  /// `--name` sets `value` to true, `--no-name` to false.
  Options& flag(const std::string& name, bool& value, const std::string& help) {
    Entry e{name, help, true, [&value] { return std::string(value ? "true" : "false"); }, {}};
    e.set = [&value](const std::string& text) { value = text == "true"; };
    entries_.push_back(std::move(e));
    return *this;
  }
  /// A positional argument (in declaration order), e.g. a mode; `value` holds the default.
  Options& positional(const std::string& name, std::string& value, const std::string& help) {
    positional_.push_back({name, help, false, [&value] { return value; }, [&value](const std::string& t) { value = t; }});
    return *this;
  }

  /// Parses argv; false when `--help` was given (the usage is printed on `help_out`).
  bool parse(int argc, const char* const* argv, std::ostream* help_out = nullptr) {
    std::size_t next_positional = 0;
    for (int i = 1; i < argc; ++i) {
      std::string a = argv[i];
      if (a == "--help" || a == "-h") {
        if (help_out) usage(*help_out);
        return false;
      }
      if (a.rfind("--", 0) != 0) {
        ALEFSI_CHECK_ARG(next_positional < positional_.size(), a, "unexpected argument; see --help");
        positional_[next_positional++].set(a);
        continue;
      }
      a = a.substr(2);
      std::string text;
      bool has_text = false;
      if (const auto eq = a.find('='); eq != std::string::npos) text = a.substr(eq + 1), a = a.substr(0, eq), has_text = true;
      Entry* e = find(a);
      if (!e && a.rfind("no-", 0) == 0 && (e = find(a.substr(3))) && e->is_flag) {
        ALEFSI_CHECK_ARG(!has_text, "--" + a, "is a flag: it takes no value");
        e->set("false");
        continue;
      }
      ALEFSI_CHECK_ARG(e != nullptr, "--" + a, "unknown option; see --help");
      if (e->is_flag) {
        ALEFSI_CHECK_ARG(!has_text, "--" + a, "is a flag: it takes no value");
        e->set("true");
        continue;
      }
      if (!has_text) {
        ALEFSI_CHECK_ARG(i + 1 < argc, "--" + a, "needs a value");
        text = argv[++i];
      }
      e->set(text);
    }
    return true;
  }
  bool parse(int argc, char** argv, std::ostream& help_out) { return parse(argc, argv, &help_out); }

  /// What `--help` prints: the summary, then every option with its default and help.
  void usage(std::ostream& out) const {
    out << "usage: " << program_;
    for (const auto& p : positional_) out << " [" << p.name << "]";
    out << " [options]\n" << summary_ << "\n";
    for (const auto& p : positional_) out << "  " << std::left << std::setw(24) << p.name << p.help << " (default " << p.get() << ")\n";
    for (const auto& e : entries_) {
      const std::string key = "--" + e.name + (e.is_flag ? "" : " X");
      out << "  " << std::left << std::setw(24) << key << e.help << " (default " << e.get() << ")\n";
    }
    out << "  " << std::left << std::setw(24) << "--help" << "this text\n";
  }
  /// One line with the value of every option (for the log of a run), itself a valid command line.
  void print(std::ostream& out) const {
    out << program_;
    for (const auto& p : positional_) out << ' ' << p.get();
    for (const auto& e : entries_) {
      if (e.is_flag) out << (e.get() == "true" ? " --" : " --no-") << e.name;
      else out << " --" << e.name << ' ' << e.get();
    }
    out << '\n';
  }

 private:
  struct Entry {
    std::string name, help;
    bool is_flag = false;
    std::function<std::string()> get;
    std::function<void(const std::string&)> set;
  };
  Entry* find(const std::string& name) {
    for (auto& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }
  template <class T>
  static T convert(const std::string& name, const std::string& text) {
    if constexpr (std::is_same_v<T, std::string>) {
      return text;
    } else if constexpr (std::is_same_v<T, std::filesystem::path>) {
      return std::filesystem::path(text);
    } else if constexpr (detail::is_option_list<T>) {  // comma-separated; each item converted as one value
      T out;
      std::stringstream ss(text);
      for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(convert<typename T::value_type>(name, item));
      return out;
    } else if constexpr (std::is_floating_point_v<T>) {
      std::size_t used = 0;
      T v{};
      try {
        v = T(std::stod(text, &used));
      } catch (const std::exception&) {
        used = 0;
      }
      ALEFSI_CHECK_ARG(used == text.size() && !text.empty() && std::isfinite(v), "--" + name, "expects a finite number, got '",
                       text, "'");
      return v;
    } else {
      static_assert(std::is_integral_v<T>, "Options::add: unsupported option type");
      T v{};
      const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
      ALEFSI_CHECK_ARG(ec == std::errc() && p == text.data() + text.size(), "--" + name, "expects an integer, got '", text,
                       "'");
      return v;
    }
  }
  template <class T>
  static std::string show(const T& v) {
    if constexpr (std::is_same_v<T, std::string>) {
      return v.empty() ? std::string("''") : v;
    } else if constexpr (std::is_same_v<T, std::filesystem::path>) {
      return v.empty() ? std::string("''") : v.string();
    } else if constexpr (detail::is_option_list<T>) {
      std::string s;
      for (const auto& x : v) s += (s.empty() ? "" : ",") + show(x);
      return s.empty() ? std::string("''") : s;
    } else {
      std::ostringstream o;
      o << v;
      return o.str();
    }
  }

  std::string program_, summary_;
  std::vector<Entry> entries_, positional_;
};

}  // namespace alefsi
