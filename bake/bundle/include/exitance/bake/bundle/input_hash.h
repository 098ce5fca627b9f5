// SHA-256 of the input file, recorded in the manifest (and keying caches).
#pragma once
#include <string>

namespace exitance {

// Lower-case hex. Throws std::runtime_error when the file cannot be read.
std::string sha256_of_file(const std::string& path);

}  // namespace exitance
