#pragma once

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>

namespace millsim {

/// A problem with what the user asked for (a config file, a command-line value). The message
/// is complete and meant to be printed as it is: it names the file, line and key where known.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Which side of a limit the allowed values lie on, for limit_text.
enum class Allowed { above, below };

/// A computed limit for a refusal's "allowed:" part, in the fewest significant digits from six
/// that still lie on the allowed side of it, so that the message never seems to refuse a value
/// it allows: 3 × 0.0508 = 0.15239999999999998 as a least slab length is "0.1524" (0.1524 is
/// allowed), a cone's 0.16378660541979106 as a bound from above "0.1637866", not "0.1638".
inline std::string limit_text(double limit, Allowed allowed) {
  for (int digits = 6; digits < 17; ++digits) {
    std::string text = fmt::format("{:.{}g}", limit, digits);
    double read = 0.0;
    std::from_chars(text.data(), text.data() + text.size(), read);
    if (allowed == Allowed::above ? read >= limit : read <= limit) return text;
  }
  return fmt::format("{}", limit);  // the shortest form that reads back as the limit itself
}

/// A value a warning reports as beyond a threshold ("X, more than T"), in `digits` significant
/// digits, or in more where fewer would read as the threshold itself or as on its other side:
/// 9.9987 steps against "fewer than 10" is "9.999", not "10"; 5.004 % against "more than 5 %"
/// is "5.004", not "5".
inline std::string beyond_text(double value, double threshold, int digits = 3) {
  for (int shown = digits; shown < 17; ++shown) {
    std::string text = fmt::format("{:.{}g}", value, shown);
    double read = 0.0;
    std::from_chars(text.data(), text.data() + text.size(), read);
    if (value > threshold ? read > threshold : value < threshold ? read < threshold : true) {
      return text;
    }
  }
  return fmt::format("{}", value);
}

/// A count of time steps computed from the user's values, for a refusal: "1.7e+13", or "more
/// than 1.7e+308" when it overflowed (a time step of 1e-310 s gave "inf steps"; a double
/// overflows from about 1.798e308).
inline std::string step_count_text(double count, double most) {
  if (!std::isfinite(count)) return "more than 1.7e+308";
  // Three digits, unless they would read as allowed: 1.0000001e10 against at most 1e10.
  const std::string text = fmt::format("{:.3g}", count);
  double read = 0.0;
  std::from_chars(text.data(), text.data() + text.size(), read);
  return count > most && read <= most ? limit_text(count, Allowed::above) : text;
}

}  // namespace millsim
