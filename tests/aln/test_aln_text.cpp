// Tests of the ALN text format (thesis Figure 5.4): exact round trip and hostile input.
#include <cstddef>
#include <cstdio>
#include <cstring>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/text_format.h"
#include "aln_test_util.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

namespace aln = boticelli::aln;

namespace {
using ModelF = aln::Aln<float, 3, 64>;
using ModelD = aln::Aln<double, 2, 16>;
ModelF g_f;
ModelF g_g;
char g_text[65536];
char g_text2[65536];

template <typename M>
bool identical(const M& a, const M& b) {
  if (a.piece_count() != b.piece_count() || a.node_count() != b.node_count()) return false;
  // Same tree shape (node numbering may differ): walk both together.
  std::size_t stack[2 * 128][2];
  std::size_t top = 0;
  stack[top][0] = 0;
  stack[top][1] = 0;
  ++top;
  while (top > 0) {
    --top;
    const auto x = a.node(stack[top][0]);
    const auto y = b.node(stack[top][1]);
    if (x.kind != y.kind) return false;
    if (x.kind == aln::NodeKind::kPiece) {
      if (x.a != y.a) return false;
      continue;
    }
    stack[top][0] = x.a;
    stack[top][1] = y.a;
    stack[top + 1][0] = x.b;
    stack[top + 1][1] = y.b;
    top += 2;
  }
  for (std::size_t p = 0; p < a.piece_count(); ++p) {
    const auto& u = a.piece(p);
    const auto& v = b.piece(p);
    if (std::memcmp(u.weight.data(), v.weight.data(), sizeof(u.weight)) != 0 ||
        std::memcmp(u.centroid.data(), v.centroid.data(), sizeof(u.centroid)) != 0 ||
        std::memcmp(&u.centroid_output, &v.centroid_output, sizeof(u.centroid_output)) != 0 ||
        std::memcmp(&u.bias, &v.bias, sizeof(u.bias)) != 0) {
      return false;
    }
  }
  for (int i = 0; i < M::kInputs; ++i) {
    if (a.input_range(i).lo != b.input_range(i).lo || a.input_range(i).hi != b.input_range(i).hi) {
      return false;
    }
  }
  return a.output_range().lo == b.output_range().lo && a.output_range().hi == b.output_range().hi;
}

// Thesis Figure 5.4 (the ALN of a 2D occupancy function), with its typesetting slips
// ("e - 019", a missing '+') repaired.
const char* const kFigure54 =
    "VARIABLES = 3:\n"
    "x0 : [0, 100];\n"
    "x1 : [0, 100];\n"
    "x2 : [-0.100000000000001, 1.10000000000001];\n"
    "OUTPUT = x2;\n"
    "LINEARFORMS = 8;\n"
    "0 : -0.0025775417471730249 (x0 - 68.406933942514058) +\n"
    " 0.00097339244428427496 (x1 - 5.2084780444034102) - 1 (x2 - 0.0091314141451077861);\n"
    "1 : -3.473863743550066e-013 (x0 - 47.251255792582434) +\n"
    "  4.1563576567829662e-013 (x1 - 13.160881035134665) - 1 (x2 - 4.9063554368901343e-012);\n"
    "2 : 0.00016062073088807331 (x0 - 39.786671388398872) +\n"
    " 0.27508702928044448 (x1 - 28.655593772023508) - 1 (x2 - 0.62594933920327589);\n"
    "3 : -5.4931402340175244e-019 (x0 - 44.432716144393254) +\n"
    "  1.3666804381996871e-017 (x1 - 38.450723277018646) - 1 (x2 - 0.999999999999999999);\n"
    "4 : -1.6221746004891314e-031 (x0 - 14.634643492882514) -\n"
    " 3.359150903932276e-032 (x1 - 40.880839341599732) - 1 (x2 - 7.9796233328002509e-032);\n"
    "5 : 7.2701086463233145e-064 (x0 - 6.7833882297211661) +\n"
    " 1.9110809581926726e-063 (x1 - 24.723279572639708) - 1 (x2 - 3.1360567225957893e-062);\n"
    "6 : 0.37157500203172533 (x0 - 17.657355731337013) +\n"
    " 0.0011219898249259102 (x1 - 34.622157550187197) - 1 (x2 - 0.62070213711450717);\n"
    "7 : 0.3752589541124618 (x0 - 17.546701092500417) +\n"
    " 0.00012452206178189317 (x1 - 41.886512024589692) - 1 (x2 - 0.57993755330086338);\n"
    "BLOCKS = 1;\n"
    "0 : MIN(MAX(MIN(0, 1), MIN(2, 3)), MAX(MIN(4, 5), MIN(6, 7)));\n";
}  // namespace

TEST_GROUP(AlnText){};

TEST(AlnText, WritingAndReadingGivesTheSameModelBitForBit) {
  aln_test::Rng rng(41);
  for (int m = 0; m < 6; ++m) {
    aln_test::random_model(g_f, 1 + static_cast<std::size_t>(m) * 12, rng);
    g_f.set_input_range(1, -2.5F, 1e-3F);
    const std::size_t n = aln::write_text(g_f, g_text, sizeof(g_text));
    CHECK(n > 0);
    aln::TextError err;
    CHECK_TEXT(aln::read_text(g_text, n, g_g, err), err.what());
    CHECK(identical(g_f, g_g));
    const std::size_t n2 = aln::write_text(g_g, g_text2, sizeof(g_text2));
    LONGS_EQUAL(n, n2);
    STRCMP_EQUAL(g_text, g_text2);
  }
}

TEST(AlnText, DoubleModelsRoundTripExactlyToo) {
  static ModelD a;
  static ModelD b;
  aln_test::Rng rng(43);
  aln_test::random_model(a, 16, rng);
  const std::size_t n = aln::write_text(a, g_text, sizeof(g_text));
  aln::TextError err;
  CHECK_TEXT(aln::read_text(g_text, n, b, err), err.what());
  CHECK(identical(a, b));
}

TEST(AlnText, ReadsTheThesisFigure) {
  static ModelD a;
  aln::TextError err;
  CHECK_TEXT(aln::read_text(kFigure54, std::strlen(kFigure54), a, err), err.what());
  LONGS_EQUAL(8, a.piece_count());
  DOUBLES_EQUAL(-0.100000000000001, a.output_range().lo, 1e-15);
  // Piece 2 through its centroid.
  const aln::Piece<double, 2>& p = a.piece(2);
  DOUBLES_EQUAL(0.62594933920327589, p.value(p.centroid), 1e-12);
  // Far along x1 in the middle of x0, the wall piece 3 (occupancy ~1) caps the function.
  const auto e = a.evaluate(Eigen::Vector2d(40.0, 90.0));
  CHECK(e.value > 0.9 && e.value <= 1.0 + 1e-9);
  const std::size_t n = aln::write_text(a, g_text, sizeof(g_text));
  CHECK(n > 0);
  CHECK(std::strstr(g_text,
                    "BLOCKS = 1;\n0 : MIN(MAX(MIN(0, 1), MIN(2, 3)), MAX(MIN(4, 5), "
                    "MIN(6, 7)));") != nullptr);
}

TEST(AlnText, NamesAndTheOutputPositionAreFree) {
  static ModelD a;
  const char* text =
      "VARIABLES = 3:\n m : [0, 1];\n alpha : [-3, 3];\n h : [0, 20];\n OUTPUT = m;\n"
      "LINEARFORMS = 3;\n"
      "0 : -1 (m - 0.5) + 0.25 (alpha + 1) - 0 (h - 2);\n"
      "1 : 2 (h - 0) - 1 (m - 0) + 0 (alpha - 0);\n"
      "2 : 0 (alpha - 0) + 0 (h - 0) - 1 (m - 0.75);\n"
      "BLOCKS = 1;\n0 : MAX(0, 1, 2);\n";
  aln::TextError err;
  CHECK_TEXT(aln::read_text(text, std::strlen(text), a, err), err.what());
  LONGS_EQUAL(3, a.piece_count());
  // At alpha = -1, h = 0.1: MAX(0.5, 0.2, 0.75) = 0.75.
  DOUBLES_EQUAL(0.75, a.evaluate(Eigen::Vector2d(-1.0, 0.1)).value, 1e-12);
  DOUBLES_EQUAL(-3.0, a.input_range(0).lo, 0.0);
  DOUBLES_EQUAL(1.0, a.output_range().hi, 0.0);
}

TEST(AlnText, MalformedTextIsRejectedWithALineNumber) {
  struct Case {
    const char* text;
    std::size_t line;
  };
  const Case cases[] = {
      {"", 1},
      {"VARIABLES = 4:\n", 1},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [1, 0];\n", 3},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = y;\n", 5},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx0 : [0, 1];\n", 3},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 1;\n0 : 1 (x0 - 0) + 1 (x1 - 0) - 2 (x2 - 0);\n",
       7},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 1;\n0 : 1 (x0 - 0) + 1 (x0 - 0) - 1 (x2 - 0);\n",
       7},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 999;\n",
       6},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 1;\n0 : 1e999 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n",
       7},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 2;\n0 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n"
       "1 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 1;\n0 : MIN(0, 0);\n",
       10},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 2;\n0 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n"
       "1 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 1;\n0 : MIN(0, 2);\n",
       10},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 2;\n0 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n"
       "1 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 1;\n0 : MIN(0, 1;\n",
       10},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 2;\n0 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n"
       "1 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 1;\n0 : MIN(0, 1); extra\n",
       10},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 2;\n0 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n"
       "1 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 1;\n0 : MAX(0);\n",
       10},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 1;\n0 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 2;\n",
       8},
      {"VARIABLES = 3:\nx0 : [0, 1];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
       "LINEARFORMS = 1;\n0 : 1 (x0 - 0) $ 1 (x1 - 0) - 1 (x2 - 0);\n",
       7},
  };
  for (const Case& c : cases) {
    static ModelD m;
    aln::TextError err;
    CHECK_FALSE(aln::read_text(c.text, std::strlen(c.text), m, err));
    CHECK(std::strlen(err.what()) > 10);
    if (err.line != c.line) {
      std::printf("\nunexpected line %zu (want %zu): %s\n", err.line, c.line, err.what());
    }
    LONGS_EQUAL(c.line, err.line);
    CHECK(std::strstr(err.what(), "line ") != nullptr);
  }
}

TEST(AlnText, AFailedReadLeavesTheModelUnchanged) {
  aln_test::Rng rng(47);
  aln_test::random_model(g_f, 12, rng);
  aln_test::random_model(g_g, 12, rng);
  const std::size_t n = aln::write_text(g_f, g_text, sizeof(g_text));
  aln::TextError err;
  CHECK_FALSE(aln::read_text(g_text, n - 4, g_g, err));  // cut inside the block
  CHECK_FALSE(identical(g_f, g_g));
  CHECK(aln::read_text(g_text, n, g_g, err));
  CHECK(identical(g_f, g_g));
}

TEST(AlnText, DeepNestingBeyondCapacityIsAnErrorNotACrash) {
  static aln::Aln<double, 1, 4> m;
  std::size_t used = static_cast<std::size_t>(std::snprintf(
      g_text, sizeof(g_text),
      "VARIABLES = 2:\nx0 : [0, 1];\nx1 : [0, 1];\nOUTPUT = x1;\nLINEARFORMS = 2;\n"
      "0 : 1 (x0 - 0) - 1 (x1 - 0);\n1 : 2 (x0 - 0) - 1 (x1 - 0);\nBLOCKS = 1;\n0 : "));
  for (int i = 0; i < 12000; ++i) {
    std::memcpy(g_text + used, "MIN(", 4);
    used += 4;
  }
  aln::TextError err;
  CHECK_FALSE(aln::read_text(g_text, used, m, err));
  CHECK(std::strstr(err.what(), "nested") != nullptr);
}

TEST(AlnText, TruncatedAndCorruptedTextNeverCrashes) {
  aln_test::Rng rng(53);
  aln_test::random_model(g_f, 6, rng);
  const std::size_t n = aln::write_text(g_f, g_text, sizeof(g_text));
  std::size_t accepted = 0;
  for (std::size_t cut = 0; cut < n; ++cut) {
    aln::TextError err;
    if (aln::read_text(g_text, cut, g_g, err)) {
      ++accepted;
    } else {
      CHECK(err.line >= 1);
    }
  }
  LONGS_EQUAL(1, accepted);  // only the cut that drops the final newline
  const char alphabet[] = "MINAX()0123456789,;:[]=+-.e x\n\t$";
  for (int trial = 0; trial < 3000; ++trial) {
    std::memcpy(g_text2, g_text, n);
    for (int flips = 0; flips < 3; ++flips) {
      g_text2[rng.below(n)] = alphabet[rng.below(sizeof(alphabet) - 1)];
    }
    aln::TextError err;
    if (!aln::read_text(g_text2, n, g_g, err)) CHECK(err.what()[0] != '\0');
  }
}

TEST(AlnText, WritingToASmallBufferFailsCleanly) {
  aln_test::Rng rng(59);
  aln_test::random_model(g_f, 8, rng);
  char small[64];
  LONGS_EQUAL(0, aln::write_text(g_f, small, sizeof(small)));
  STRCMP_EQUAL("", small);
}

TEST(AlnText, ReadingAndWritingDoNotAllocate) {
  aln_test::Rng rng(61);
  aln_test::random_model(g_f, 40, rng);
  std::size_t n = 0;
  bool ok = false;
  aln::TextError err;
  CHECK_NO_ALLOCATION(n = aln::write_text(g_f, g_text, sizeof(g_text)));
  CHECK_NO_ALLOCATION(ok = aln::read_text(g_text, n, g_g, err));
  CHECK(ok);
}

TEST(AlnText, AFormThatOverflowsSomewhereInItsInputRangesIsRejectedAndTheModelKept) {
  // 1e307 per unit of x0 over [0, 100]: finite at the centroid, past the largest double at
  // x0 = 100. Read as the 2-input double model.
  const char* text =
      "VARIABLES = 3:\nx0 : [0, 100];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
      "LINEARFORMS = 2;\n0 : 1e307 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n"
      "1 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 1;\n0 : MIN(0, 1);\n";
  static ModelD m;
  const std::size_t before = m.piece_count();
  aln::TextError err;
  CHECK_FALSE(aln::read_text(text, std::strlen(text), m, err));
  STRCMP_CONTAINS("overflows", err.what());
  LONGS_EQUAL(before, m.piece_count());
  // The same form with x0 only up to 10 reads (1e308 < the largest double).
  const char* fits =
      "VARIABLES = 3:\nx0 : [0, 10];\nx1 : [0, 1];\nx2 : [0, 1];\nOUTPUT = x2;\n"
      "LINEARFORMS = 2;\n0 : 1e307 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\n"
      "1 : 1 (x0 - 0) + 1 (x1 - 0) - 1 (x2 - 0);\nBLOCKS = 1;\n0 : MIN(0, 1);\n";
  CHECK_TRUE(aln::read_text(fits, std::strlen(fits), m, err));
  LONGS_EQUAL(2, m.piece_count());
}
