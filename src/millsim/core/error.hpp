#pragma once

#include <stdexcept>
#include <string>

namespace millsim {

/// A problem with what the user asked for (a config file, a command-line value). The message
/// is complete and meant to be printed as it is: it names the file, line and key where known.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace millsim
