// Bad input: reported as one line "FILE: ELEMENT: PROBLEM", exit status 2, nothing written.
#pragma once
#include <stdexcept>
#include <string>

namespace exitance {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string element, std::string problem)
      : std::runtime_error(file + ": " + element + ": " + problem),
        file_(std::move(file)), element_(std::move(element)), problem_(std::move(problem)) {}
  const std::string& file() const { return file_; }
  const std::string& element() const { return element_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_, element_, problem_;
};

}  // namespace exitance
