// FaultInjection: what the console's `fault` command asks of a board that can make its
// devices fail on purpose (the sim board; hardware boards have none).
#pragma once

#include <cstddef>
#include <string_view>

#include "firmware/common/text_buffer.h"

namespace boticelli::firmware {

class FaultInjection {
 public:
  virtual ~FaultInjection() = default;
  // Makes `device` fail as `type` from now for `seconds` (0 = until the end of the run).
  // True with the reply's text in `reply` ("fault camera off seconds=5.0 from_t_s=12.30"),
  // false with the reason there (an unknown name, a pair that means nothing, a full plan).
  // Never allocates.
  virtual bool inject(std::string_view device, std::string_view type, double seconds,
                      TextBufferBase& reply) = 0;
  // One line per active fault, "fault DEVICE TYPE since_t_s=X until_t_s=Y|end\r\n".
  virtual void describe_active(TextBufferBase& out) const = 0;

 protected:
  FaultInjection() = default;
  FaultInjection(const FaultInjection&) = default;
  FaultInjection& operator=(const FaultInjection&) = default;
};

}  // namespace boticelli::firmware
