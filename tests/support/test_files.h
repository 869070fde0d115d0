// Scratch files for tests: read a whole file, write one, make a fresh directory under /tmp.
#pragma once

#include <string>

namespace boticelli::test {

// The file's bytes; empty if it cannot be opened.
std::string read_file(const std::string& path);
// Writes (replaces) the file with these bytes; fails the test if it cannot be opened.
void write_file(const std::string& path, const std::string& bytes);
// A new directory /tmp/boticelli-<what>-XXXXXX; fails the test if it cannot be made.
std::string temp_dir(const char* what);

}  // namespace boticelli::test
