// The formula compiler's internals (formula.hpp), shared by its three parts:
//   formula_parser.cpp    text -> expression tree (Node), with typed errors at their column;
//   formula_compiler.cpp  folding, fused register code (Instruction), compile();
//   formula_vm.cpp        Program: the scalar reference and the vectorised loops.
// Internal to levelset_core.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "formula/formula.hpp"

namespace levelset::formula {

namespace detail {

inline constexpr const char* kVarNames[kVarCount] = {"d",    "x",    "y",   "z",   "nx",  "ny",  "nz",  "H",
                                              "K",    "k1",   "k2",  "grad", "t",  "h",   "kavg", "dist",
                                              "dgx",  "dgy",  "dgz", "dn",  "img", "edge", "roi"};


enum class Op : std::uint8_t {
  Const, Var, Neg, Not, Add, Sub, Mul, Div, Pow, Lt, Le, Gt, Ge, Eq, Ne, And, Or, Select,
  Abs, Sign, Sqrt, Cbrt, Exp, Log, Sin, Cos, Tan, Asin, Acos, Atan, Floor, Ceil,
  Atan2, Min, Max, Step, Clamp, Smoothstep
};

struct Function {
  const char* name;
  Op op;
  int arity;
};
inline constexpr Function kFunctions[] = {
    {"abs", Op::Abs, 1},     {"sign", Op::Sign, 1},   {"sqrt", Op::Sqrt, 1},   {"cbrt", Op::Cbrt, 1},
    {"exp", Op::Exp, 1},     {"log", Op::Log, 1},     {"sin", Op::Sin, 1},     {"cos", Op::Cos, 1},
    {"tan", Op::Tan, 1},     {"asin", Op::Asin, 1},   {"acos", Op::Acos, 1},   {"atan", Op::Atan, 1},
    {"floor", Op::Floor, 1}, {"ceil", Op::Ceil, 1},   {"atan2", Op::Atan2, 2}, {"pow", Op::Pow, 2},
    {"min", Op::Min, 2},     {"max", Op::Max, 2},     {"step", Op::Step, 2},   {"clamp", Op::Clamp, 3},
    {"smoothstep", Op::Smoothstep, 3}};

inline const Function* find_function(std::string_view name) {
  for (const Function& f : kFunctions)
    if (name == f.name) return &f;
  return nullptr;
}

struct Node {
  Op op = Op::Const;
  double value = 0;                 // Const
  int var = 0;                      // Var
  std::array<int, 3> arg{-1, -1, -1};
  int args = 0;
  int column = 1;
  int height = 1;                   // of the subtree: bounds the recursion of fold, emit, eval
};

// ---- evaluation of one operation (double reference and float vectors share the rules) ----
template <typename T>
[[gnu::always_inline]] inline T apply(Op op, T a, T b, T c) {
  switch (op) {
    case Op::Neg: return -a;
    case Op::Not: return a == T(0) ? T(1) : T(0);
    case Op::Add: return a + b;
    case Op::Sub: return a - b;
    case Op::Mul: return a * b;
    case Op::Div: return a / b;
    case Op::Pow: return std::pow(a, b);
    case Op::Lt: return a < b ? T(1) : T(0);
    case Op::Le: return a <= b ? T(1) : T(0);
    case Op::Gt: return a > b ? T(1) : T(0);
    case Op::Ge: return a >= b ? T(1) : T(0);
    case Op::Eq: return a == b ? T(1) : T(0);
    case Op::Ne: return a != b ? T(1) : T(0);
    case Op::And: return (a != T(0) && b != T(0)) ? T(1) : T(0);
    case Op::Or: return (a != T(0) || b != T(0)) ? T(1) : T(0);
    case Op::Select: return a != T(0) ? b : c;
    case Op::Abs: return std::abs(a);
    case Op::Sign: return a > T(0) ? T(1) : (a < T(0) ? T(-1) : T(0));
    case Op::Sqrt: return std::sqrt(a);
    case Op::Cbrt: return std::cbrt(a);
    case Op::Exp: return std::exp(a);
    case Op::Log: return std::log(a);
    case Op::Sin: return std::sin(a);
    case Op::Cos: return std::cos(a);
    case Op::Tan: return std::tan(a);
    case Op::Asin: return std::asin(a);
    case Op::Acos: return std::acos(a);
    case Op::Atan: return std::atan(a);
    case Op::Floor: return std::floor(a);
    case Op::Ceil: return std::ceil(a);
    case Op::Atan2: return std::atan2(a, b);
    case Op::Min: return std::min(a, b);
    case Op::Max: return std::max(a, b);
    case Op::Step: return b >= a ? T(1) : T(0);
    case Op::Clamp: return std::min(std::max(a, b), c);
    case Op::Smoothstep: {
      const T s = std::min(std::max((c - a) / (b - a), T(0)), T(1));
      return s * s * (T(3) - T(2) * s);
    }
    case Op::Const:
    case Op::Var: break;
  }
  return T(0);
}

// Slots: [0, kVarCount) input variables, kVarCount + r register r.
inline bool fusable(Op op) {
  return op == Op::Add || op == Op::Sub || op == Op::Mul || op == Op::Div || op == Op::Min || op == Op::Max;
}

// Fused modifiers of the arithmetic instructions (Add Sub Mul Div Min Max): each operand may
// be negated or taken by absolute value as it is read, and the result negated, taken by
// absolute value or square-rooted as it is written. '-sign(H)*sqrt(K+abs(K))' then runs as 3
// passes over the samples instead of 6; a product's operands may also be read as sign(v) or
// -sign(v), which makes the thesis's mean-Gaussian speed 2 passes.
enum class Mod : std::uint8_t { None, Neg, Abs, Sqrt, Sign, NegSign };  // Sign, NegSign: Mul's operands only

struct Instruction {
  Op op;
  int dst;                     // register
  std::array<int, 3> src{-1, -1, -1};  // slots: < kVarCount an input variable, else kVarCount + register
  float value = 0;             // Const
  Mod mod_a = Mod::None, mod_b = Mod::None, post = Mod::None;
};

// Tree height cap whatever the limits say: recursion over the tree stays shallow (a frame is
// about 100 bytes; 4096 levels fit any thread's stack).
inline constexpr int kMaxHeight = 4096;

// formula_parser.cpp: the tree of `text` (its root in root), checked against options.limits.
std::vector<Node> parse(std::string_view text, const CompileOptions& options, int& root);
// formula_compiler.cpp: constant subtrees folded (returns the new index of node i).
int fold(std::vector<Node>& nodes, int i);
// The scalar reference: the tree evaluated in double.
double eval_tree(const std::vector<Node>& nodes, int i, const std::array<double, kVarCount>& values);

}  // namespace detail

struct Program::Code {
  std::vector<detail::Node> nodes;     // folded tree, for the scalar reference
  int root = -1;
  std::vector<detail::Instruction> code;
  int registers = 0;
  int result_slot = -1;        // slot holding the result
};

struct ProgramAccess {
  static void set(Program& p, std::string text, std::uint32_t uses, std::vector<detail::Node> nodes, int root,
                  std::vector<detail::Instruction> code, int registers, int result) {
    p.text_ = std::move(text);
    p.uses_ = uses;
    p.code_->nodes = std::move(nodes);
    p.code_->root = root;
    p.code_->code = std::move(code);
    p.code_->registers = registers;
    p.code_->result_slot = result;
  }
};

}  // namespace levelset::formula
