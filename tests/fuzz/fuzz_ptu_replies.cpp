// libFuzzer target: the PTU-D46 reply stream, byte by byte through the line assembler and each
// completed line through the reply parser.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "hal/codec/ptu46_codec.h"

namespace ptu = boticelli::codec::ptu46;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ptu::LineAssembler lines;
  for (std::size_t i = 0; i < size; ++i) {
    if (!lines.push(static_cast<char>(data[i]))) continue;
    const std::string_view line = lines.line();
    if (line.size() > ptu::kMaxLineLength) std::abort();
    const ptu::Reply r = ptu::parse_reply(line);
    if (r.has_value && !std::isfinite(r.value)) std::abort();
    if (r.skipped > line.size()) std::abort();
    if (!r.text.empty() && (r.text.data() < line.data() ||
                            r.text.data() + r.text.size() > line.data() + line.size())) {
      std::abort();  // the reply text must point into the line
    }
    double value = 0.0;
    if (ptu::parse_number(line, value) && !std::isfinite(value)) std::abort();
  }
  return 0;
}
