// libFuzzer target: the ALN text format. Every text read_text accepts must evaluate to finite
// values inside its domain and write back to a text that reads as the same model.
#include <cmath>
#include <cstdio>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "algo/aln/aln.h"
#include "algo/aln/text_format.h"

namespace {

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_aln_text: %s\n", what);
  std::abort();
}

char g_text[1 << 17];

// Reads the input as a model of type M; when accepted, checks it and its round trip.
template <typename M>
void check(const char* text, std::size_t size, M& model, M& again) {
  constexpr int N = M::kInputs;
  boticelli::aln::TextError err;
  if (!boticelli::aln::read_text(text, size, model, err)) {
    if (err.line < 1 || err.what()[0] == '\0') fail("a rejected text without a line or reason");
    return;
  }
  // Finite everywhere in its input box: the corners and the centre.
  for (int corner = 0; corner <= (1 << N); ++corner) {
    typename M::Vec x;
    bool finite = true;
    for (int i = 0; i < N; ++i) {
      const auto r = model.input_range(i);
      using S = typename M::ScalarType;
      const S t = corner == (1 << N) ? S(0.5) : static_cast<S>((corner >> i) & 1);
      x(i) = r.lo + t * (r.hi - r.lo);
      finite = finite && std::isfinite(x(i));
    }
    if (finite && !std::isfinite(model.evaluate(x).value)) {
      fail("an accepted model evaluates non-finite inside its ranges");
    }
  }
  const std::size_t n = boticelli::aln::write_text(model, g_text, sizeof g_text / 2);
  if (n == 0) fail("an accepted model does not write back");
  if (!boticelli::aln::read_text(g_text, n, again, err)) fail("a written model does not read");
  const std::size_t m = boticelli::aln::write_text(again, g_text + n, sizeof g_text / 2);
  if (m != n || std::memcmp(g_text, g_text + n, n) != 0) fail("the round trip changed the model");
}

// The occupancy model (3 inputs, float) and the thesis figure's 2-input model (double).
boticelli::aln::Aln<float, 3, 256> g_model3;
boticelli::aln::Aln<float, 3, 256> g_again3;
boticelli::aln::Aln<double, 2, 64> g_model2;
boticelli::aln::Aln<double, 2, 64> g_again2;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto* text = reinterpret_cast<const char*>(data);
  check(text, size, g_model3, g_again3);
  check(text, size, g_model2, g_again2);
  return 0;
}
