// Firmware entry: parse options, report version and board (the mission comes in a later stage).
#include "firmware/firmware_main.h"

#include <cstdio>

#include "firmware/options.h"

namespace boticelli::firmware {

int firmware_main(int argc, const char* const* argv, Board& board) {
  const BoardInfo& info = board.info();
  Options options;
  const ParseResult parsed = parse_options(argc, argv, info.simulated, options);
  if (!parsed.ok) {
    std::fprintf(stderr, "boticelli: %s\n%s", parsed.error, usage_text());
    return 2;
  }
  if (options.show_help) {
    std::fputs(usage_text(), stdout);
    return 0;
  }
  std::printf("boticelli %s board=%s (%s)\n", BOTICELLI_VERSION, info.name, info.description);
  return 0;
}

}  // namespace boticelli::firmware
