#pragma once
// The message of the exception a call throws, for tests that assert what an error says.
#include <exception>
#include <functional>
#include <string>

namespace dgtex::test {

// what() of the Exception that `call` throws, "" when it throws none. Exceptions of other
// types propagate (and fail the test).
template <class Exception = std::exception>
std::string message_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const Exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace dgtex::test
