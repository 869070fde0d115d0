// Settings from the environment and the list of world files, shared by the suites that run worlds.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace boticelli::bench {

// The environment variable as a positive integer, else `fallback`.
long env_long(const char* name, long fallback);
// The environment variable as a number, else `fallback`.
double env_double(const char* name, double fallback);

// Whether `name` is one of the comma-separated entries of `list`; every name is when `list`
// is null or empty (an unset filter variable).
bool listed(const char* list, std::string_view name);

// The environment variable `dir_env` if set, else `fallback` (a folder of *.sdf worlds).
std::string worlds_dir(const char* dir_env, const char* fallback);

// The worlds in `dir` (file names without ".sdf", sorted), restricted by the environment
// variable `filter_env` = name[,name...] (with or without ".sdf") when it is set; a listed
// name that is not in `dir` is reported on stderr with the `suite` prefix (unless
// !report_missing: the caller looks in several folders) and skipped.
std::vector<std::string> world_names(const std::string& dir, const char* filter_env,
                                     const char* suite, bool report_missing = true);

}  // namespace boticelli::bench
