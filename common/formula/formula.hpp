// Speed formulas (thesis 4.7): a small expression language compiled once and evaluated over
// whole bricks, for speed functions typed by users (and arriving from the network).
//
// Language: numbers (1, 2.5, 1e-3), + - * / ^ (right associative, above unary minus:
//   -x^2 = -(x^2)), unary - and !, comparisons < <= > >= == != (1 or 0), && || (nonzero is
//   true; both sides are evaluated), cond ? a : b, parentheses; functions abs sign sqrt cbrt
//   exp log sin cos tan asin acos atan floor ceil (1 argument), atan2 pow min max step (2;
//   step(edge, x) = x >= edge ? 1 : 0), clamp(x, lo, hi), smoothstep(e0, e1, x) (3); constant
//   pi. Variables: see Var (d x y z nx ny nz H K k1 k2 grad t h kavg, and the fields dist dgx
//   dgy dgz dn img edge roi), plus the named constants given at compile time (eps = 0.1).
//   Names are case-sensitive. Unknown names, wrong arity, bad syntax: Error{ParseError}.
// Compilation: parse (recursive descent, depth-limited), check names and arity, fold
//   constant subexpressions, emit a linear program of vector instructions over registers.
// Evaluation: each instruction runs over all n <= 512 samples (a brick's active voxels)
//   before the next: a tight loop per operation, not a tree walk per voxel. Single precision
//   (the band's values are floats); evaluate_scalar is the double reference.
// Errors: Error{ParseError} whose reason holds the message, then the formula and a caret line
//   under the offending column (1-based column also in `where`: "formula:column N");
//   Error{LimitExceeded} for a formula longer than limits.max_length, nested deeper than
//   limits.max_depth or compiling to more than limits.max_instructions; Error{InvalidArgument}
//   for a constant that is not finite or shadows a variable or function name.
// Safety: parsing recursion is bounded by max_depth; the expression tree's height (long
//   left-associative chains are built by loops) is capped at 4096 whatever the limits, so
//   folding, code generation and scalar evaluation recurse boundedly; allocation is
//   proportional to the formula's length; nothing is reachable outside the grammar.
// Threading: a Program is immutable after compile; evaluate is const and thread-safe with
//   one Workspace per thread.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace levelset::formula {

enum class Var : std::uint8_t {
  d, x, y, z, nx, ny, nz, H, K, k1, k2, grad, t, h, kavg,
  dist, dgx, dgy, dgz, dn, img, edge, roi,
  count
};
inline constexpr int kVarCount = int(Var::count);
const char* var_name(Var v);
// Var of a name, or Var::count.
Var var_from_name(std::string_view name);

struct Limits {
  std::size_t max_length = 4096;  // characters
  int max_depth = 64;             // nesting of parentheses, calls, operators
  int max_instructions = 1024;
};

struct CompileOptions {
  std::map<std::string, double, std::less<>> constants;  // e.g. {"eps", 0.1}
  Limits limits;
};

inline constexpr int kMaxSamples = 512;

// Per-thread scratch registers for evaluate.
class Workspace {
 public:
  float* reg(int i, int n_regs);
 private:
  std::vector<float> data_;
};

class Program {
 public:
  Program();
  ~Program();
  Program(const Program&);
  Program& operator=(const Program&);
  Program(Program&&) noexcept;
  Program& operator=(Program&&) noexcept;

  const std::string& text() const { return text_; }
  // Bit (1 << int(Var)) for each variable the formula reads (after constant folding).
  std::uint32_t uses() const { return uses_; }
  bool uses_var(Var v) const { return (uses_ >> int(v)) & 1u; }
  int instruction_count() const;
  // The folded constant when the formula does not depend on any variable.
  bool is_constant() const;
  double constant_value() const;

  // out[i] for i < n (n <= kMaxSamples): inputs[int(Var)] points at n floats for every
  // variable in uses() (others may be null).
  void evaluate(const std::array<const float*, kVarCount>& inputs, int n, float* out, Workspace& ws) const;
  // Double-precision reference for one sample.
  double evaluate_scalar(const std::array<double, kVarCount>& values) const;

 private:
  friend struct ProgramAccess;
  std::string text_;
  std::uint32_t uses_ = 0;
  struct Code;
  std::unique_ptr<Code> code_;
};

Program compile(std::string_view text, const CompileOptions& options = {});

// The formula's top-level sum split into the terms that read curvatures (H K k1 k2 kavg) and
// the rest, each compiled on its own (an empty side compiles to the constant 0): the speed's
// parabolic and advective parts (evolve/speed.hpp). Same errors as compile.
struct SplitProgram {
  Program without_curvature;
  Program with_curvature;
};
SplitProgram compile_split_by_curvature(std::string_view text, const CompileOptions& options = {});

}  // namespace levelset::formula
