// How the command-line programs (bake, exitance-relight, exitance-view) report an error: one line
// "PROGRAM: error: ..." on stderr (DESIGN: bad input is a one-line error naming the problem).
#pragma once
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>

namespace exitance {

// `text` with its line breaks made spaces, so a message from a library stays one line.
inline std::string one_line(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  return text;
}

// The exit status after CLI11 failed to parse the options: --help (and CLI11's other exits with
// status 0) printed as CLI11 prints them, any other failure one line and 2 (CLI11's own print is
// two lines, its message and "Run with --help").
inline int exit_for_option_error(CLI::App& app, const CLI::ParseError& error, const char* program) {
  if (error.get_exit_code() == 0) return app.exit(error);
  std::cerr << program << ": error: " << one_line(error.what()) << "\n";
  return 2;
}

}  // namespace exitance
