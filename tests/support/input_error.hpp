#pragma once
// Checking that a call throws boicp::InputError, and reading its message.

#include <string>

#include <gtest/gtest.h>

#include "boicp/util/types.hpp"

namespace boicp::test {

/// Runs `call` and returns the InputError message, failing the test when
/// nothing (or something else) is thrown.
template <typename Call>
std::string InputErrorMessage(Call call) {
  try {
    call();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return {};
}

}  // namespace boicp::test
