// Scratch files for tests (test_files.h).
#include "test_files.h"

#include <stdlib.h>

#include <cstdio>

#include "CppUTest/TestHarness.h"

namespace boticelli::test {

std::string read_file(const std::string& path) {
  std::string out;
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return out;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  std::fclose(f);
  return out;
}

void write_file(const std::string& path, const std::string& bytes) {
  FILE* f = std::fopen(path.c_str(), "wb");
  CHECK_TEXT(f != nullptr, path.c_str());
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
}

std::string temp_dir(const char* what) {
  std::string templ = std::string("/tmp/boticelli-") + what + "-XXXXXX";
  const char* dir = mkdtemp(templ.data());
  CHECK(dir != nullptr);
  return dir;
}

}  // namespace boticelli::test
