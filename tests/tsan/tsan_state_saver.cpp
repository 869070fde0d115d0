// ThreadSanitizer check of the state writer: the executive's thread submits states and
// parameter files (as `param save` does) while the writer thread saves them, with the
// counters and the last errors read from both sides; the files must end as the newest ones. A plain
// program (CppUTest's operator new collides with ThreadSanitizer's), exit code 0 on success; any
// race report halts it.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "firmware/state/mission_state.h"
#include "firmware/state/persistence.h"
#include "firmware/state/state_saver.h"

namespace fw = boticelli::firmware;

namespace {

fw::MissionState g_state;
fw::MissionState g_loaded;
fw::StateStore g_store;

void make_state(std::uint64_t cycle, fw::MissionState& s) {
  s.clear();
  s.cycle = cycle;
  s.seed = 7;
  s.pose = {0.1F * static_cast<float>(cycle), -0.25F, 0.01F};
  for (std::uint64_t i = 0; i < cycle % 40; ++i) {
    (void)s.obstacles.push_back({static_cast<float>(i), static_cast<float>(cycle)});
  }
  s.add_log(cycle, "cycle done");
}

int fail(const char* what) {
  std::fprintf(stderr, "tsan_state_saver: %s\n", what);
  return 1;
}

}  // namespace

int main() {
  char templ[] = "/tmp/boticelli-tsan-XXXXXX";
  const char* dir = mkdtemp(templ);
  if (dir == nullptr) return fail("no temporary directory");
  char error[256] = "";
  if (!g_store.open(dir, error, sizeof error)) return fail(error);
  int status = 0;
  for (int round = 0; round < 3 && status == 0; ++round) {
    auto saver = std::make_unique<fw::StateSaver>(g_store);
    saver->start();
    char parameters[64] = "";
    for (std::uint64_t c = 1; c <= 200; ++c) {
      make_state(c, g_state);
      // Read the counters after every submit, taken or not: the writer updates them after
      // each save, with no other hand-over in between, so an unguarded access races with it
      // for certain, not only when the try_lock happens to meet the writer.
      bool taken = false;
      while (!taken) {
        taken = saver->submit(g_state);
        (void)saver->saved();
        (void)saver->failures();
        saver->last_error(error, sizeof error);
      }
      std::snprintf(parameters, sizeof parameters, "gain = %llu\n",
                    static_cast<unsigned long long>(c));
      while (saver->submit_parameters(parameters) == fw::StateSaver::Submitted::kBusy) {
        (void)saver->parameter_saves();
        (void)saver->parameter_failures();
        (void)saver->parameter_error(error, sizeof error);
      }
    }
    saver->flush();
    if (saver->failures() != 0 || saver->parameter_failures() != 0) status = fail("a save failed");
    char last[64] = "";
    FILE* f = std::fopen((std::string(dir) + "/parameters.conf").c_str(), "rb");
    if (f == nullptr) return fail("no parameters file");
    last[std::fread(last, 1, sizeof last - 1, f)] = '\0';
    std::fclose(f);
    if (std::strcmp(last, "gain = 200\n") != 0) status = fail("the parameters are not the newest");
    if (saver->saved() < 1 || saver->saved() > 200) status = fail("implausible save count");
    saver.reset();  // joins the writer
    if (g_store.load(g_loaded, error, sizeof error) != fw::LoadResult::kLoaded) {
      status = fail(error);
    } else {
      make_state(200, g_state);
      if (!(g_loaded == g_state)) status = fail("the file is not the newest state");
    }
  }
  const std::string base(dir);
  for (const char* name :
       {"/mission.state.a", "/mission.state.b", "/mission.state.a.tmp", "/mission.state.b.tmp"}) {
    unlink((base + name).c_str());
  }
  unlink((base + "/parameters.conf").c_str());
  rmdir(dir);
  if (status == 0) std::printf("tsan_state_saver: ok\n");
  return status;
}
