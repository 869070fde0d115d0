// Settings from the environment and the list of world files (see bench_worlds.h).
#include "bench_worlds.h"

#include <dirent.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace boticelli::bench {

long env_long(const char* name, long fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  const long n = std::strtol(v, nullptr, 10);
  return n > 0 ? n : fallback;
}

double env_double(const char* name, double fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  return std::atof(v);
}

std::string worlds_dir(const char* dir_env, const char* fallback) {
  const char* dir = std::getenv(dir_env);
  return dir != nullptr && *dir != '\0' ? std::string(dir) : std::string(fallback);
}

namespace {
bool strip_sdf(std::string& name) {
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".sdf") == 0) {
    name.resize(name.size() - 4);
    return true;
  }
  return false;
}
}  // namespace

bool listed(const char* list, std::string_view name) {
  if (list == nullptr || *list == '\0') return true;
  const std::string_view names(list);
  std::size_t begin = 0;
  while (begin <= names.size()) {
    const std::size_t end = std::min(names.find(',', begin), names.size());
    if (names.substr(begin, end - begin) == name) return true;
    begin = end + 1;
  }
  return false;
}

std::vector<std::string> world_names(const std::string& dir, const char* filter_env,
                                     const char* suite, bool report_missing) {
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str()); d != nullptr) {
    while (const dirent* e = ::readdir(d)) {
      std::string n = e->d_name;
      if (strip_sdf(n)) names.push_back(n);
    }
    ::closedir(d);
  }
  std::sort(names.begin(), names.end());
  const char* only = std::getenv(filter_env);
  if (only == nullptr || *only == '\0') return names;
  std::vector<std::string> wanted;
  std::stringstream list(only);
  std::string item;
  while (std::getline(list, item, ',')) {
    (void)strip_sdf(item);
    if (std::find(names.begin(), names.end(), item) != names.end()) {
      wanted.push_back(item);
    } else if (report_missing) {
      std::fprintf(stderr, "%s: no world '%s' in %s\n", suite, item.c_str(), dir.c_str());
    }
  }
  return wanted;
}

}  // namespace boticelli::bench
