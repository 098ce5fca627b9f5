// Bad input to exitance-view (a missing or malformed bundle, an option out of range, an output it
// cannot write): one line naming the file or option and the problem; the tool exits 2 for it.
#pragma once
#include <stdexcept>
#include <string>

namespace exitance::view {

struct ViewInputError : std::runtime_error {
  explicit ViewInputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace exitance::view
