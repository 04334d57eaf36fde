#pragma once
// Errors in tests and command-line tools: the message of an expected InputError, and the exit
// status convention of the tools (0 ok, 1 a check failed, 2 bad input, 3 any other error).
#include <exception>
#include <functional>
#include <iostream>
#include <string>

#include "base/errors.h"

namespace vbrdf {
namespace test {

// The message of the InputError that f() throws; "" when it throws none (other exceptions pass).
template <class F> std::string error_of(F f) {
  try {
    f();
  } catch (const InputError &e) {
    return e.what();
  }
  return "";
}

// Runs a tool's body: its status, or "error: <message>" on stderr and 2 for an InputError, 3 for
// any other exception.
inline int run_tool(const std::function<int()> &body) {
  try {
    return body();
  } catch (const InputError &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 3;
  }
}

} // namespace test
} // namespace vbrdf
