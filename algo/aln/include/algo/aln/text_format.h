// ALN text format after thesis Figure 5.4 (VARIABLES, ranges, OUTPUT, LINEARFORMS, BLOCKS): write
// and read.
#pragma once

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>
#include <system_error>

#include "algo/aln/aln.h"

namespace boticelli::aln {

// What went wrong while reading, and where (1-based line; 0 if not about a line).
struct TextError {
  std::size_t line = 0;
  std::array<char, 160> message{};
  [[nodiscard]] const char* what() const { return message.data(); }
};

namespace text_detail {

class Writer {
 public:
  Writer(char* buffer, std::size_t size) : buffer_(buffer), size_(size) {}
  void put(const char* s) {
    while (*s != '\0') put_char(*s++);
  }
  void put_char(char c) {
    if (used_ + 1 < size_) {
      buffer_[used_] = c;
    } else {
      overflow_ = true;
    }
    ++used_;
  }
  template <typename T>
  void number(T v) {
    std::array<char, 64> tmp{};
    const auto r = std::to_chars(tmp.data(), tmp.data() + tmp.size() - 1, v);
    *r.ptr = '\0';
    put(tmp.data());
  }
  void index(std::size_t v) { number(static_cast<unsigned long long>(v)); }
  // NUL-terminates; returns characters written, 0 if the buffer was too small.
  std::size_t finish() {
    if (size_ == 0) return 0;
    if (overflow_) {
      buffer_[0] = '\0';
      return 0;
    }
    buffer_[used_] = '\0';
    return used_;
  }

 private:
  char* buffer_;
  std::size_t size_;
  std::size_t used_ = 0;
  bool overflow_ = false;
};

enum class Tok : std::uint8_t { kEnd, kName, kNumber, kPunct, kBad };

struct Token {
  Tok kind = Tok::kEnd;
  const char* begin = nullptr;
  std::size_t length = 0;
  std::size_t line = 1;
  [[nodiscard]] bool is(char c) const { return kind == Tok::kPunct && *begin == c; }
  [[nodiscard]] bool is(const char* word) const {
    return kind == Tok::kName && std::strlen(word) == length &&
           std::memcmp(word, begin, length) == 0;
  }
};

// Splits the text into names, unsigned numbers and punctuation; tracks line numbers.
class Lexer {
 public:
  static constexpr std::size_t kMaxToken = 63;
  Lexer(const char* text, std::size_t length) : p_(text), end_(text + length) {}
  Token next() {
    while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r' || *p_ == '\n')) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
    Token t;
    t.line = line_;
    t.begin = p_;
    if (p_ >= end_) return t;
    const char c = *p_;
    if (is_alpha(c)) {
      while (p_ < end_ && (is_alpha(*p_) || is_digit(*p_))) ++p_;
      t.kind = Tok::kName;
    } else if (is_digit(c) || c == '.') {
      while (p_ < end_ && (is_digit(*p_) || *p_ == '.')) ++p_;
      if (p_ < end_ && (*p_ == 'e' || *p_ == 'E')) {
        ++p_;
        if (p_ < end_ && (*p_ == '+' || *p_ == '-')) ++p_;
        while (p_ < end_ && is_digit(*p_)) ++p_;
      }
      t.kind = Tok::kNumber;
    } else if (std::strchr("=:[],;()+-", c) != nullptr && c != '\0') {
      ++p_;
      t.kind = Tok::kPunct;
    } else {
      ++p_;
      t.kind = Tok::kBad;
    }
    t.length = static_cast<std::size_t>(p_ - t.begin);
    if (t.length > kMaxToken) t.kind = Tok::kBad;
    return t;
  }

 private:
  static bool is_alpha(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
  }
  static bool is_digit(char c) { return c >= '0' && c <= '9'; }
  const char* p_;
  const char* end_;
  std::size_t line_ = 1;
};

}  // namespace text_detail

// Writes `model` as text: inputs x0..x{N-1}, output xN, each piece in the Eq 5.5 form
// "w0 (x0 - c0) + w1 (x1 - c1) - 1 (xN - cy);" and one block with the MIN/MAX expression.
// Numbers use the shortest form that reads back to the same bits, so write -> read is exact.
// Returns the characters written (NUL-terminated), or 0 if `size` is too small.
template <typename Scalar, int N, std::size_t MaxPieces>
std::size_t write_text(const Aln<Scalar, N, MaxPieces>& model, char* buffer, std::size_t size) {
  text_detail::Writer w(buffer, size);
  const auto var = [&](int i) {
    w.put_char('x');
    w.index(static_cast<std::size_t>(i));
  };
  const auto range = [&](Range<Scalar> r) {
    w.put(" : [");
    w.number(r.lo);
    w.put(", ");
    w.number(r.hi);
    w.put("];\n");
  };
  w.put("VARIABLES = ");
  w.index(static_cast<std::size_t>(N + 1));
  w.put(":\n");
  for (int i = 0; i < N; ++i) {
    var(i);
    range(model.input_range(i));
  }
  var(N);
  range(model.output_range());
  w.put("OUTPUT = ");
  var(N);
  w.put(";\nLINEARFORMS = ");
  w.index(model.piece_count());
  w.put(";\n");
  const auto centred = [&](int i, Scalar c) {
    w.put(" (");
    var(i);
    w.put(std::signbit(c) ? " + " : " - ");
    w.number(std::fabs(c));
    w.put_char(')');
  };
  for (std::size_t p = 0; p < model.piece_count(); ++p) {
    const auto& piece = model.piece(p);
    w.index(p);
    w.put(" : ");
    for (int i = 0; i < N; ++i) {
      const Scalar wi = piece.weight(i);
      if (i == 0) {
        w.number(wi);
      } else {
        w.put(std::signbit(wi) ? " - " : " + ");
        w.number(std::fabs(wi));
      }
      centred(i, piece.centroid(i));
    }
    w.put(" - 1");
    centred(N, piece.centroid_output);
    w.put(";\n");
  }
  w.put("BLOCKS = 1;\n0 : ");
  // Pre-order walk with an explicit stack; ')' and ',' are pushed as markers.
  constexpr std::uint32_t kClose = 0xFFFF0000U;
  constexpr std::uint32_t kComma = 0xFFFE0000U;
  std::array<std::uint32_t, 3 * MaxPieces> stack{};
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t item = stack[--top];
    if (item == kClose) {
      w.put_char(')');
      continue;
    }
    if (item == kComma) {
      w.put(", ");
      continue;
    }
    const auto& n = model.node(item);
    if (n.kind == NodeKind::kPiece) {
      w.index(n.a);
      continue;
    }
    w.put(n.kind == NodeKind::kMin ? "MIN(" : "MAX(");
    stack[top++] = kClose;
    stack[top++] = n.b;
    stack[top++] = kComma;
    stack[top++] = n.a;
  }
  w.put(";\n");
  return w.finish();
}

// Reads text written by write_text (or by hand after Figure 5.4: any variable names, the
// output may be any of the variables, forms may wrap lines, MIN/MAX may take more than two
// arguments). Needs N + 1 variables, at most MaxPieces forms and exactly one block that uses
// every form once. On failure returns false, fills `error` with a message and line number
// and leaves `model` unchanged. Bounded: no recursion, every size checked against capacity.
// Weight bounds are not part of the format; `model` keeps its own.
template <typename Scalar, int N, std::size_t MaxPieces>
bool read_text(const char* text, std::size_t length, Aln<Scalar, N, MaxPieces>& model,
               TextError& error) {
  using text_detail::Tok;
  using text_detail::Token;
  using Model = Aln<Scalar, N, MaxPieces>;
  using PieceType = Piece<Scalar, N>;
  constexpr std::size_t kVars = static_cast<std::size_t>(N) + 1;
  text_detail::Lexer lex(text == nullptr ? "" : text, text == nullptr ? 0 : length);
  Token tok = lex.next();
  bool failed = false;
  const auto fail = [&](const char* what) {
    if (failed) return false;
    failed = true;
    error.line = tok.line;
    char seen[24] = {};
    if (tok.kind == Tok::kEnd) {
      std::snprintf(seen, sizeof(seen), "end of text");
    } else {
      const std::size_t n = tok.length < 16 ? tok.length : 16;
      std::memcpy(seen, tok.begin, n);
    }
    std::snprintf(error.message.data(), error.message.size(), "line %zu: %s (at '%s')", tok.line,
                  what, seen);
    return false;
  };
  const auto advance = [&]() { tok = lex.next(); };
  const auto expect = [&](char c, const char* what) {
    if (!tok.is(c)) return fail(what);
    advance();
    return true;
  };
  const auto expect_word = [&](const char* word, const char* what) {
    if (!tok.is(word)) return fail(what);
    advance();
    return true;
  };
  // [sign] number, exactly as written (Scalar precision).
  const auto number = [&](Scalar& out, const char* what) {
    bool negative = false;
    if (tok.is('-') || tok.is('+')) {
      negative = tok.is('-');
      advance();
    }
    if (tok.kind != Tok::kNumber) return fail(what);
    Scalar v{};
    const auto r = std::from_chars(tok.begin, tok.begin + tok.length, v);
    if (r.ec != std::errc() || r.ptr != tok.begin + tok.length || !std::isfinite(v)) {
      return fail("bad number");
    }
    out = negative ? -v : v;
    advance();
    return true;
  };
  const auto count = [&](std::size_t& out, std::size_t max, const char* what) {
    if (tok.kind != Tok::kNumber) return fail(what);
    unsigned long long v = 0;
    const auto r = std::from_chars(tok.begin, tok.begin + tok.length, v);
    if (r.ec != std::errc() || r.ptr != tok.begin + tok.length) return fail(what);
    if (v > max) return fail("number too large for this model");
    out = static_cast<std::size_t>(v);
    advance();
    return true;
  };

  // VARIABLES = n: name : [lo, hi]; ...
  std::array<std::array<char, 32>, kVars> names{};
  std::array<Range<Scalar>, kVars> ranges{};
  if (!expect_word("VARIABLES", "expected VARIABLES")) return false;
  if (!expect('=', "expected '='")) return false;
  std::size_t vars = 0;
  if (!count(vars, 1000000, "expected the number of variables")) return false;
  if (vars != kVars) return fail("wrong number of variables for this model");
  if (!expect(':', "expected ':' after the number of variables")) return false;
  for (std::size_t v = 0; v < kVars; ++v) {
    if (tok.kind != Tok::kName || tok.length >= names[v].size()) {
      return fail("expected a variable name");
    }
    std::memcpy(names[v].data(), tok.begin, tok.length);
    for (std::size_t u = 0; u < v; ++u) {
      if (std::strcmp(names[u].data(), names[v].data()) == 0) return fail("duplicate variable");
    }
    advance();
    if (!expect(':', "expected ':' after the variable name")) return false;
    if (!expect('[', "expected '['")) return false;
    if (!number(ranges[v].lo, "expected the lower end of the range")) return false;
    if (!expect(',', "expected ','")) return false;
    if (!number(ranges[v].hi, "expected the upper end of the range")) return false;
    if (!(ranges[v].lo <= ranges[v].hi)) return fail("range has lower end above upper end");
    if (!expect(']', "expected ']'")) return false;
    if (!expect(';', "expected ';'")) return false;
  }
  const auto find_var = [&](const Token& t) -> std::size_t {
    for (std::size_t v = 0; v < kVars; ++v) {
      if (t.kind == Tok::kName && std::strlen(names[v].data()) == t.length &&
          std::memcmp(names[v].data(), t.begin, t.length) == 0) {
        return v;
      }
    }
    return kVars;
  };
  // OUTPUT = name;
  if (!expect_word("OUTPUT", "expected OUTPUT")) return false;
  if (!expect('=', "expected '='")) return false;
  const std::size_t output = find_var(tok);
  if (output == kVars) return fail("OUTPUT is not one of the variables");
  advance();
  if (!expect(';', "expected ';'")) return false;
  // Map text variables to model inputs: the non-output variables in order.
  std::array<int, kVars> input_of{};
  {
    int next = 0;
    for (std::size_t v = 0; v < kVars; ++v) input_of[v] = v == output ? -1 : next++;
  }
  // LINEARFORMS = L; index : terms;
  if (!expect_word("LINEARFORMS", "expected LINEARFORMS")) return false;
  if (!expect('=', "expected '='")) return false;
  std::size_t forms = 0;
  if (!count(forms, MaxPieces, "expected the number of linear forms")) return false;
  if (forms == 0) return fail("need at least one linear form");
  if (!expect(';', "expected ';'")) return false;
  std::array<PieceType, MaxPieces> pieces{};
  for (std::size_t f = 0; f < forms; ++f) {
    std::size_t index = 0;
    if (!count(index, forms, "expected the linear form's index")) return false;
    if (index != f) return fail("linear forms must be numbered 0, 1, 2, ... in order");
    if (!expect(':', "expected ':' after the form's index")) return false;
    std::array<Scalar, kVars> weight{};
    std::array<Scalar, kVars> centre{};
    std::array<bool, kVars> have{};
    for (std::size_t t = 0; t < kVars; ++t) {
      bool negative = false;
      if (t > 0) {
        if (!tok.is('+') && !tok.is('-')) return fail("expected '+' or '-' between terms");
        negative = tok.is('-');
        advance();
      }
      Scalar wv{};
      if (!number(wv, "expected a weight")) return false;
      if (negative) wv = -wv;
      if (!expect('(', "expected '(' after the weight")) return false;
      const std::size_t v = find_var(tok);
      if (v == kVars) return fail("unknown variable");
      if (have[v]) return fail("variable appears twice in one form");
      have[v] = true;
      advance();
      bool plus = false;
      if (tok.is('+') || tok.is('-')) {
        plus = tok.is('+');
        advance();
      } else {
        return fail("expected '-' or '+' before the centroid");
      }
      Scalar cv{};
      if (!number(cv, "expected the centroid")) return false;
      if (!expect(')', "expected ')'")) return false;
      weight[v] = wv;
      centre[v] = plus ? -cv : cv;
    }
    if (weight[output] != Scalar(-1)) return fail("the output's weight must be -1");
    if (!expect(';', "expected ';' at the end of the form")) return false;
    typename PieceType::Vec w;
    typename PieceType::Vec c;
    for (std::size_t v = 0; v < kVars; ++v) {
      if (v == output) continue;
      w(input_of[v]) = weight[v];
      c(input_of[v]) = centre[v];
    }
    pieces[f].set(w, c, centre[output]);
  }
  // BLOCKS = 1; 0 : expression;
  if (!expect_word("BLOCKS", "expected BLOCKS")) return false;
  if (!expect('=', "expected '='")) return false;
  std::size_t blocks = 0;
  if (!count(blocks, 1000000, "expected the number of blocks")) return false;
  if (blocks != 1) return fail("exactly one block is supported");
  if (!expect(';', "expected ';'")) return false;
  std::size_t block = 0;
  if (!count(block, 0, "expected block 0")) return false;
  if (!expect(':', "expected ':' after the block's index")) return false;
  // Iterative parse of MIN/MAX(...) with an explicit, bounded stack.
  struct Frame {
    NodeKind kind;
    int acc;  // node index of the left fold so far, -1 if none
    std::size_t args;
  };
  std::array<Frame, MaxPieces> stack{};
  std::array<typename Model::Node, Model::kMaxNodes> nodes{};
  std::array<bool, MaxPieces> used{};
  std::size_t node_count = 0;
  std::size_t top = 0;
  int root = -1;
  const auto add = [&](typename Model::Node n) -> int {
    if (node_count >= Model::kMaxNodes) return -1;
    nodes[node_count] = n;
    return static_cast<int>(node_count++);
  };
  // Gives a finished operand to the enclosing call (or makes it the root).
  const auto deliver = [&](int operand) {
    if (top == 0) {
      root = operand;
      return true;
    }
    Frame& f = stack[top - 1];
    f.args += 1;
    if (f.acc < 0) {
      f.acc = operand;
      return true;
    }
    const int n =
        add({f.kind, static_cast<std::uint16_t>(f.acc), static_cast<std::uint16_t>(operand)});
    if (n < 0) return fail("too many nodes");
    f.acc = n;
    return true;
  };
  while (true) {
    // An operand.
    if (tok.is("MIN") || tok.is("MAX")) {
      if (top >= stack.size()) return fail("MIN/MAX nested too deeply");
      stack[top++] = Frame{tok.is("MIN") ? NodeKind::kMin : NodeKind::kMax, -1, 0};
      advance();
      if (!expect('(', "expected '(' after MIN/MAX")) return false;
      continue;
    }
    std::size_t piece = 0;
    if (tok.kind != Tok::kNumber) return fail("expected MIN, MAX or a form's index");
    if (!count(piece, MaxPieces, "expected a form's index")) return false;
    if (piece >= forms) return fail("no linear form with this index");
    if (used[piece]) return fail("linear form used twice in the block");
    used[piece] = true;
    const int leaf = add({NodeKind::kPiece, static_cast<std::uint16_t>(piece), 0});
    if (leaf < 0) return fail("too many nodes");
    if (!deliver(leaf)) return false;
    // Close finished calls, then expect ',' (next operand) or the end.
    while (top > 0 && tok.is(')')) {
      const Frame f = stack[--top];
      if (f.args < 2) return fail("MIN/MAX needs at least two arguments");
      advance();
      if (!deliver(f.acc)) return false;
    }
    if (top == 0) break;
    if (!expect(',', "expected ',' or ')'")) return false;
  }
  if (!expect(';', "expected ';' at the end of the block")) return false;
  if (tok.kind != Tok::kEnd) return fail("unexpected text after the block");
  if (node_count != 2 * forms - 1) {
    return fail("the block must use every linear form exactly once");
  }
  // Put the root at node 0.
  const auto r = static_cast<std::uint16_t>(root);
  if (r != 0) {
    std::swap(nodes[0], nodes[r]);
    for (std::size_t i = 0; i < node_count; ++i) {
      auto& n = nodes[i];
      if (n.kind == NodeKind::kPiece) continue;
      if (n.a == 0) {
        n.a = r;
      } else if (n.a == r) {
        n.a = 0;
      }
      if (n.b == 0) {
        n.b = r;
      } else if (n.b == r) {
        n.b = 0;
      }
    }
  }
  // Every form finite all over the input box: |bias| + sum |w_i| max(|lo_i|, |hi_i|) bounds
  // its value there and every partial sum of evaluating it, so if that is finite no
  // evaluation in the box overflows.
  for (std::size_t f = 0; f < forms; ++f) {
    Scalar bound = std::fabs(pieces[f].bias);
    for (std::size_t v = 0; v < kVars; ++v) {
      if (v == output) continue;
      const Scalar reach = std::max(std::fabs(ranges[v].lo), std::fabs(ranges[v].hi));
      bound += std::fabs(pieces[f].weight(input_of[v])) * reach;
    }
    if (!std::isfinite(bound)) return fail("a linear form overflows over the input ranges");
  }
  if (!model.assign({nodes.data(), node_count}, {pieces.data(), forms})) {
    return fail("the block must use every linear form exactly once");
  }
  for (std::size_t v = 0; v < kVars; ++v) {
    if (v == output) {
      model.set_output_range(ranges[v].lo, ranges[v].hi);
    } else {
      model.set_input_range(input_of[v], ranges[v].lo, ranges[v].hi);
    }
  }
  error = TextError{};
  return true;
}

}  // namespace boticelli::aln
