// The one exception type of hedge: a message written for people, shown by every front end.
#pragma once

#include <stdexcept>
#include <string>

namespace hedge {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

//! Thrown when a progress callback asks to stop; the operation leaves its input untouched.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled by the user") {}
};

}  // namespace hedge
