#pragma once
// Errors about bad input (files, fields, values). Messages name the file, the field and the value,
// so a user can fix the input without reading our code.
#include <stdexcept>
#include <string>

namespace mcslam {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mcslam
