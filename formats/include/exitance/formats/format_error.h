// The one exception type of the on-disk formats and the loader: a file that cannot be used. Its
// message is one line naming the file, the element and the problem ("svo.bin: node 12: ...") so a
// tool can print it as is.
#pragma once
#include <stdexcept>
#include <string>

namespace exitance::formats {

class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The file could not be opened, read or written at all (missing, permissions, disk full), as
// opposed to a file that was read but is malformed. Lets callers (the C API) report I/O apart.
class FileAccessError : public FormatError {
 public:
  using FormatError::FormatError;
};

}  // namespace exitance::formats
