// Forked children in tests: wait for one with a time limit, so a hung child fails the test
// instead of hanging it.
#pragma once

#include <sys/types.h>

namespace boticelli::test {

// The child's wait status, or -1 when it did not end within timeout_ms (it is then killed
// and reaped).
int wait_for_child(pid_t child, int timeout_ms);

}  // namespace boticelli::test
