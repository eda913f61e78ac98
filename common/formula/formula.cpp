#include "formula/formula.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"
#include "core/suggest.hpp"

namespace levelset::formula {

namespace {

constexpr const char* kVarNames[kVarCount] = {"d",    "x",    "y",   "z",   "nx",  "ny",  "nz",  "H",
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
constexpr Function kFunctions[] = {
    {"abs", Op::Abs, 1},     {"sign", Op::Sign, 1},   {"sqrt", Op::Sqrt, 1},   {"cbrt", Op::Cbrt, 1},
    {"exp", Op::Exp, 1},     {"log", Op::Log, 1},     {"sin", Op::Sin, 1},     {"cos", Op::Cos, 1},
    {"tan", Op::Tan, 1},     {"asin", Op::Asin, 1},   {"acos", Op::Acos, 1},   {"atan", Op::Atan, 1},
    {"floor", Op::Floor, 1}, {"ceil", Op::Ceil, 1},   {"atan2", Op::Atan2, 2}, {"pow", Op::Pow, 2},
    {"min", Op::Min, 2},     {"max", Op::Max, 2},     {"step", Op::Step, 2},   {"clamp", Op::Clamp, 3},
    {"smoothstep", Op::Smoothstep, 3}};

const Function* find_function(std::string_view name) {
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

// ---- parsing ----
[[noreturn]] void fail(std::string_view text, int column, const std::string& message, ErrorCode code = ErrorCode::ParseError) {
  std::string caret(std::size_t(std::max(0, column - 1)), ' ');
  caret += '^';
  throw Error(code, "formula:column " + std::to_string(column), message + "\n  " + std::string(text) + "\n  " + caret);
}

// Tree height cap whatever the limits say: recursion over the tree stays shallow (a frame is
// about 100 bytes; 4096 levels fit any thread's stack).
constexpr int kMaxHeight = 4096;

struct Token {
  enum Kind { End, Number, Name, Sym } kind = End;
  std::string text;
  double number = 0;
  int column = 1;
};

class Parser {
 public:
  Parser(std::string_view text, const CompileOptions& options, std::vector<Node>& nodes)
      : text_(text), options_(options), nodes_(nodes) {
    advance();
  }

  int parse() {
    if (tok_.kind == Token::End) fail(text_, tok_.column, "empty formula");
    const int root = ternary(0);
    if (tok_.kind != Token::End) fail(text_, tok_.column, "unexpected '" + tok_.text + "' after the end of the formula");
    return root;
  }

 private:
  void advance() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    tok_ = Token{};
    tok_.column = int(utf8_column(text_, pos_));
    if (pos_ >= text_.size()) return;
    const char c = text_[pos_];
    if (std::isdigit(static_cast<unsigned char>(c)) || (c == '.' && pos_ + 1 < text_.size() &&
                                                         std::isdigit(static_cast<unsigned char>(text_[pos_ + 1])))) {
      std::size_t end = pos_;
      while (end < text_.size() && (std::isdigit(static_cast<unsigned char>(text_[end])) || text_[end] == '.')) ++end;
      if (end < text_.size() && (text_[end] == 'e' || text_[end] == 'E')) {
        std::size_t e = end + 1;
        if (e < text_.size() && (text_[e] == '+' || text_[e] == '-')) ++e;
        if (e < text_.size() && std::isdigit(static_cast<unsigned char>(text_[e]))) {
          end = e;
          while (end < text_.size() && std::isdigit(static_cast<unsigned char>(text_[end]))) ++end;
        }
      }
      tok_.kind = Token::Number;
      tok_.text = std::string(text_.substr(pos_, end - pos_));
      char* stop = nullptr;
      tok_.number = std::strtod(tok_.text.c_str(), &stop);
      if (stop != tok_.text.c_str() + tok_.text.size()) fail(text_, tok_.column, "malformed number '" + tok_.text + "'");
      if (!std::isfinite(tok_.number)) fail(text_, tok_.column, "number out of range '" + tok_.text + "'");
      pos_ = end;
      return;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t end = pos_;
      while (end < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[end])) || text_[end] == '_')) ++end;
      tok_.kind = Token::Name;
      tok_.text = std::string(text_.substr(pos_, end - pos_));
      pos_ = end;
      return;
    }
    static constexpr const char* kTwo[] = {"<=", ">=", "==", "!=", "&&", "||"};
    for (const char* two : kTwo)
      if (text_.substr(pos_, 2) == two) {
        tok_.kind = Token::Sym;
        tok_.text = two;
        pos_ += 2;
        return;
      }
    if (std::string_view("+-*/^()?:,<>!").find(c) != std::string_view::npos) {
      tok_.kind = Token::Sym;
      tok_.text = std::string(1, c);
      ++pos_;
      return;
    }
    const QuotedCharacter q = quote_character(text_, pos_);
    // Typographic look-alikes (pasted from documents) get the ASCII operator named.
    static constexpr std::pair<std::string_view, const char*> kLookAlikes[] = {
        {"\u2212", "-"}, {"\u2013", "-"}, {"\u00D7", "*"}, {"\u22C5", "*"}, {"\u00B7", "*"}, {"\u00F7", "/"}};
    std::string hint;
    for (const auto& [glyph, ascii] : kLookAlikes)
      if (text_.substr(pos_, glyph.size()) == glyph) hint = std::string(" (write '") + ascii + "')";
    fail(text_, tok_.column, "unexpected character " + q.text + hint);
  }

  bool is(const char* sym) const { return tok_.kind == Token::Sym && tok_.text == sym; }

  void expect(const char* sym, const std::string& what) {
    if (!is(sym)) fail(text_, tok_.column, "expected " + what + (tok_.kind == Token::End ? " before the end" : ", found '" + tok_.text + "'"));
    advance();
  }

  void enter(int depth, int column) const {
    if (depth > options_.limits.max_depth)
      fail(text_, column, "nested deeper than " + std::to_string(options_.limits.max_depth), ErrorCode::LimitExceeded);
  }

  int add(Node n) {
    // A left-associative chain (a+b+c+...) is built by a loop, not by recursion: its height
    // is bounded here, so that folding, code generation and evaluation recurse boundedly.
    for (int k = 0; k < n.args; ++k) n.height = std::max(n.height, nodes_[std::size_t(n.arg[std::size_t(k)])].height + 1);
    if (n.height > kMaxHeight)
      fail(text_, n.column, "expression nested more than " + std::to_string(kMaxHeight) + " levels",
           ErrorCode::LimitExceeded);
    nodes_.push_back(n);
    return int(nodes_.size()) - 1;
  }
  int binary(Op op, int a, int b, int column) {
    Node n;
    n.op = op;
    n.arg = {a, b, -1};
    n.args = 2;
    n.column = column;
    return add(n);
  }

  int ternary(int depth) {
    enter(depth, tok_.column);
    const int cond = logical_or(depth + 1);
    if (!is("?")) return cond;
    const int column = tok_.column;
    advance();
    const int a = ternary(depth + 1);
    expect(":", "':' of the conditional");
    const int b = ternary(depth + 1);
    Node n;
    n.op = Op::Select;
    n.arg = {cond, a, b};
    n.args = 3;
    n.column = column;
    return add(n);
  }
  int logical_or(int depth) {
    int a = logical_and(depth);
    while (is("||")) {
      const int column = tok_.column;
      advance();
      a = binary(Op::Or, a, logical_and(depth), column);
    }
    return a;
  }
  int logical_and(int depth) {
    int a = equality(depth);
    while (is("&&")) {
      const int column = tok_.column;
      advance();
      a = binary(Op::And, a, equality(depth), column);
    }
    return a;
  }
  int equality(int depth) {
    int a = relational(depth);
    while (is("==") || is("!=")) {
      const Op op = is("==") ? Op::Eq : Op::Ne;
      const int column = tok_.column;
      advance();
      a = binary(op, a, relational(depth), column);
    }
    return a;
  }
  int relational(int depth) {
    int a = additive(depth);
    while (is("<") || is("<=") || is(">") || is(">=")) {
      const Op op = is("<") ? Op::Lt : is("<=") ? Op::Le : is(">") ? Op::Gt : Op::Ge;
      const int column = tok_.column;
      advance();
      a = binary(op, a, additive(depth), column);
    }
    return a;
  }
  int additive(int depth) {
    int a = multiplicative(depth);
    while (is("+") || is("-")) {
      const Op op = is("+") ? Op::Add : Op::Sub;
      const int column = tok_.column;
      advance();
      a = binary(op, a, multiplicative(depth), column);
    }
    return a;
  }
  int multiplicative(int depth) {
    int a = unary(depth);
    while (is("*") || is("/")) {
      const Op op = is("*") ? Op::Mul : Op::Div;
      const int column = tok_.column;
      advance();
      a = binary(op, a, unary(depth), column);
    }
    return a;
  }
  int unary(int depth) {
    enter(depth, tok_.column);
    if (is("-") || is("!") || is("+")) {
      const bool plus = is("+");
      const Op op = is("-") ? Op::Neg : Op::Not;
      const int column = tok_.column;
      advance();
      const int a = unary(depth + 1);
      if (plus) return a;
      Node n;
      n.op = op;
      n.arg = {a, -1, -1};
      n.args = 1;
      n.column = column;
      return add(n);
    }
    return power(depth + 1);
  }
  int power(int depth) {
    const int base = primary(depth);
    if (!is("^")) return base;
    const int column = tok_.column;
    advance();
    return binary(Op::Pow, base, unary(depth + 1), column);
  }
  int primary(int depth) {
    enter(depth, tok_.column);
    const int column = tok_.column;
    if (tok_.kind == Token::Number) {
      Node n;
      n.value = tok_.number;
      n.column = column;
      advance();
      return add(n);
    }
    if (is("(")) {
      advance();
      const int a = ternary(depth + 1);
      expect(")", "')'");
      return a;
    }
    if (tok_.kind == Token::Name) {
      const std::string name = tok_.text;
      advance();
      if (is("(")) {
        const Function* f = find_function(name);
        if (!f) fail(text_, column, "unknown function '" + name + "'" + suggestion(name, true));
        advance();
        Node n;
        n.op = f->op;
        n.column = column;
        if (!is(")")) {
          while (true) {
            const int a = ternary(depth + 1);
            if (n.args < 3) n.arg[std::size_t(n.args)] = a;
            ++n.args;
            if (!is(",")) break;
            advance();
          }
        }
        expect(")", "')' closing " + name + "(");
        if (n.args != f->arity)
          fail(text_, column, name + " takes " + std::to_string(f->arity) + " argument" + (f->arity == 1 ? "" : "s") +
                                  ", got " + std::to_string(n.args));
        return add(n);
      }
      Node n;
      n.column = column;
      if (name == "pi") {
        n.value = std::numbers::pi;
        return add(n);
      }
      const auto c = options_.constants.find(name);
      if (c != options_.constants.end()) {
        n.value = c->second;
        return add(n);
      }
      const Var v = var_from_name(name);
      if (v == Var::count) {
        if (find_function(name)) fail(text_, column, "function '" + name + "' needs arguments: " + name + "(...)");
        fail(text_, column, "unknown name '" + name + "'" + suggestion(name, false));
      }
      n.op = Op::Var;
      n.var = int(v);
      return add(n);
    }
    if (tok_.kind == Token::End) fail(text_, column, "expected a value before the end");
    fail(text_, column, "expected a value, found '" + tok_.text + "'");
  }

  // " (did you mean 'x'?)" for a known name within edit distance 2, else "".
  std::string suggestion(const std::string& name, bool function) const {
    std::vector<std::string> names;
    if (function) {
      for (const Function& f : kFunctions) names.emplace_back(f.name);
    } else {
      for (const char* v : kVarNames) names.emplace_back(v);
      for (const auto& [k, v] : options_.constants) names.push_back(k);
      names.emplace_back("pi");
    }
    const std::string best = closest_name(name, names);
    return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
  }

  std::string_view text_;
  const CompileOptions& options_;
  std::vector<Node>& nodes_;
  std::size_t pos_ = 0;
  Token tok_;
};

// ---- folding ----
int fold(std::vector<Node>& nodes, int i) {
  Node& n = nodes[std::size_t(i)];
  if (n.op == Op::Const || n.op == Op::Var) return i;
  bool all_const = true;
  for (int k = 0; k < n.args; ++k) {
    const int a = fold(nodes, nodes[std::size_t(i)].arg[std::size_t(k)]);
    nodes[std::size_t(i)].arg[std::size_t(k)] = a;
    all_const &= nodes[std::size_t(a)].op == Op::Const;
  }
  Node& m = nodes[std::size_t(i)];
  if (!all_const) return i;
  auto val = [&](int k) { return k < m.args ? nodes[std::size_t(m.arg[std::size_t(k)])].value : 0.0; };
  const double v = apply<double>(m.op, val(0), val(1), val(2));
  m.op = Op::Const;
  m.value = v;
  m.args = 0;
  return i;
}

double eval_tree(const std::vector<Node>& nodes, int i, const std::array<double, kVarCount>& values) {
  const Node& n = nodes[std::size_t(i)];
  if (n.op == Op::Const) return n.value;
  if (n.op == Op::Var) return values[std::size_t(n.var)];
  double a[3] = {0, 0, 0};
  for (int k = 0; k < n.args; ++k) a[k] = eval_tree(nodes, n.arg[std::size_t(k)], values);
  return apply<double>(n.op, a[0], a[1], a[2]);
}

}  // namespace

// ---- program ----
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

struct Program::Code {
  std::vector<Node> nodes;     // folded tree, for the scalar reference
  int root = -1;
  std::vector<Instruction> code;
  int registers = 0;
  int result_slot = -1;        // slot holding the result
};

namespace {

// Slots: [0, kVarCount) input variables, kVarCount + r register r.
bool fusable(Op op) {
  return op == Op::Add || op == Op::Sub || op == Op::Mul || op == Op::Div || op == Op::Min || op == Op::Max;
}

int emit(const std::vector<Node>& nodes, int i, std::vector<Instruction>& code, int& registers) {
  const Node& n = nodes[std::size_t(i)];
  if (n.op == Op::Var) return n.var;
  // A negation, absolute value or square root of an arithmetic result: fused into it.
  if ((n.op == Op::Neg || n.op == Op::Abs || n.op == Op::Sqrt) && fusable(nodes[std::size_t(n.arg[0])].op)) {
    const int r = emit(nodes, n.arg[0], code, registers);
    Instruction& last = code.back();
    if (last.dst == r - kVarCount && last.post == Mod::None) {
      last.post = n.op == Op::Neg ? Mod::Neg : n.op == Op::Abs ? Mod::Abs : Mod::Sqrt;
      return r;
    }
    Instruction in;  // (not reached: the arithmetic node was just emitted last)
    in.op = n.op;
    in.src[0] = r;
    in.dst = registers++;
    code.push_back(in);
    return kVarCount + in.dst;
  }
  Instruction in;
  in.op = n.op;
  if (n.op == Op::Const) {
    in.value = float(n.value);
  } else if (fusable(n.op)) {
    // Operands that are a negation or an absolute value are read through a modifier.
    Mod* mods[2] = {&in.mod_a, &in.mod_b};
    for (int k = 0; k < 2; ++k) {
      int child = n.arg[std::size_t(k)];
      const Op cop = nodes[std::size_t(child)].op;
      const auto inner = [&](int c) { return nodes[std::size_t(nodes[std::size_t(c)].arg[0])]; };
      if (n.op == Op::Mul && cop == Op::Neg && inner(child).op == Op::Sign) {
        *mods[k] = Mod::NegSign;
        child = inner(child).arg[0];
      } else if (n.op == Op::Mul && cop == Op::Sign) {
        *mods[k] = Mod::Sign;
        child = nodes[std::size_t(child)].arg[0];
      } else if (cop == Op::Neg || cop == Op::Abs) {
        *mods[k] = cop == Op::Neg ? Mod::Neg : Mod::Abs;
        child = nodes[std::size_t(child)].arg[0];
      }
      in.src[std::size_t(k)] = emit(nodes, child, code, registers);
    }
  } else {
    for (int k = 0; k < n.args; ++k) in.src[std::size_t(k)] = emit(nodes, n.arg[std::size_t(k)], code, registers);
  }
  in.dst = registers++;
  code.push_back(in);
  return kVarCount + in.dst;
}

void collect_uses(const std::vector<Node>& nodes, int i, std::uint32_t& uses) {
  const Node& n = nodes[std::size_t(i)];
  if (n.op == Op::Var) uses |= 1u << n.var;
  for (int k = 0; k < n.args; ++k) collect_uses(nodes, n.arg[std::size_t(k)], uses);
}

bool reads_curvature(const std::vector<Node>& nodes, int i) {
  std::uint32_t uses = 0;
  collect_uses(nodes, i, uses);
  constexpr std::uint32_t curvature = 1u << int(Var::H) | 1u << int(Var::K) | 1u << int(Var::k1) |
                                      1u << int(Var::k2) | 1u << int(Var::kavg);
  return (uses & curvature) != 0;
}

}  // namespace

const char* var_name(Var v) { return int(v) < kVarCount ? kVarNames[int(v)] : "?"; }

Var var_from_name(std::string_view name) {
  for (int i = 0; i < kVarCount; ++i)
    if (name == kVarNames[i]) return Var(i);
  return Var::count;
}

float* Workspace::reg(int i, int n_regs) {
  const std::size_t need = std::size_t(n_regs) * kMaxSamples;
  if (data_.size() < need) data_.resize(need);
  return data_.data() + std::size_t(i) * kMaxSamples;
}

Program::Program() : code_(std::make_unique<Code>()) {}
Program::~Program() = default;
Program::Program(const Program& o) : text_(o.text_), uses_(o.uses_), code_(std::make_unique<Code>(*o.code_)) {}
Program& Program::operator=(const Program& o) {
  if (this != &o) {
    text_ = o.text_;
    uses_ = o.uses_;
    code_ = std::make_unique<Code>(*o.code_);
  }
  return *this;
}
Program::Program(Program&&) noexcept = default;
Program& Program::operator=(Program&&) noexcept = default;

int Program::instruction_count() const { return int(code_->code.size()); }
bool Program::is_constant() const { return code_->root >= 0 && code_->nodes[std::size_t(code_->root)].op == Op::Const; }
double Program::constant_value() const { return is_constant() ? code_->nodes[std::size_t(code_->root)].value : 0.0; }

double Program::evaluate_scalar(const std::array<double, kVarCount>& values) const {
  return eval_tree(code_->nodes, code_->root, values);
}

namespace {

template <Mod M>
[[gnu::always_inline]] inline float modify(float v) {
  if constexpr (M == Mod::Neg) return -v;
  else if constexpr (M == Mod::Abs) return std::abs(v);
  else if constexpr (M == Mod::Sqrt) return std::sqrt(v);
  // Sign as a difference of comparisons: branch-free, so the loop vectorises.
  else if constexpr (M == Mod::Sign) return float(v > 0.0f) - float(v < 0.0f);
  else if constexpr (M == Mod::NegSign) return float(v < 0.0f) - float(v > 0.0f);
  else return v;
}

template <Op O, Mod A, Mod B, Mod P>
void fused(const float* a, const float* b, float* d, int n) {
  for (int i = 0; i < n; ++i) d[i] = modify<P>(apply<float>(O, modify<A>(a[i]), modify<B>(b[i]), 0.0f));
}

template <Op O, Mod A, Mod B>
void fused_post(Mod p, const float* a, const float* b, float* d, int n) {
  switch (p) {
    case Mod::Neg: return fused<O, A, B, Mod::Neg>(a, b, d, n);
    case Mod::Abs: return fused<O, A, B, Mod::Abs>(a, b, d, n);
    case Mod::Sqrt: return fused<O, A, B, Mod::Sqrt>(a, b, d, n);
    default: return fused<O, A, B, Mod::None>(a, b, d, n);
  }
}

template <Op O, Mod A>
void fused_b(Mod mb, Mod p, const float* a, const float* b, float* d, int n) {
  switch (mb) {
    case Mod::Neg: return fused_post<O, A, Mod::Neg>(p, a, b, d, n);
    case Mod::Abs: return fused_post<O, A, Mod::Abs>(p, a, b, d, n);
    case Mod::Sign:
      if constexpr (O == Op::Mul) return fused_post<O, A, Mod::Sign>(p, a, b, d, n);
      break;
    case Mod::NegSign:
      if constexpr (O == Op::Mul) return fused_post<O, A, Mod::NegSign>(p, a, b, d, n);
      break;
    default: break;
  }
  return fused_post<O, A, Mod::None>(p, a, b, d, n);
}

template <Op O>
void fused_a(const Instruction& in, const float* a, const float* b, float* d, int n) {
  switch (in.mod_a) {
    case Mod::Neg: return fused_b<O, Mod::Neg>(in.mod_b, in.post, a, b, d, n);
    case Mod::Abs: return fused_b<O, Mod::Abs>(in.mod_b, in.post, a, b, d, n);
    case Mod::Sign:
      if constexpr (O == Op::Mul) return fused_b<O, Mod::Sign>(in.mod_b, in.post, a, b, d, n);
      break;
    case Mod::NegSign:
      if constexpr (O == Op::Mul) return fused_b<O, Mod::NegSign>(in.mod_b, in.post, a, b, d, n);
      break;
    default: break;
  }
  return fused_b<O, Mod::None>(in.mod_b, in.post, a, b, d, n);
}

void fused_loop(const Instruction& in, const float* a, const float* b, float* d, int n) {
  switch (in.op) {
    case Op::Add: return fused_a<Op::Add>(in, a, b, d, n);
    case Op::Sub: return fused_a<Op::Sub>(in, a, b, d, n);
    case Op::Mul: return fused_a<Op::Mul>(in, a, b, d, n);
    case Op::Div: return fused_a<Op::Div>(in, a, b, d, n);
    case Op::Min: return fused_a<Op::Min>(in, a, b, d, n);
    case Op::Max: return fused_a<Op::Max>(in, a, b, d, n);
    default: break;
  }
}

}  // namespace

void Program::evaluate(const std::array<const float*, kVarCount>& inputs, int n, float* out, Workspace& ws) const {
  if (n <= 0) return;
  if (n > kMaxSamples) throw Error(ErrorCode::InvalidArgument, "formula", "more than 512 samples in one evaluation");
  const Code& c = *code_;
  const int regs = std::max(c.registers, 1);
  ws.reg(regs - 1, regs);  // size once
  auto slot = [&](int s) -> const float* { return s < kVarCount ? inputs[std::size_t(s)] : ws.reg(s - kVarCount, regs); };
  for (const Instruction& in : c.code) {
    float* d = ws.reg(in.dst, regs);
    if (in.op == Op::Const) {
      std::fill_n(d, n, in.value);
      continue;
    }
    const float* a = slot(in.src[0]);
    const float* b = in.src[1] >= 0 ? slot(in.src[1]) : a;  // unused operands alias a
    const float* e = in.src[2] >= 0 ? slot(in.src[2]) : a;
    if (fusable(in.op)) {
      fused_loop(in, a, b, d, n);
      continue;
    }
    // One tight loop per operation (the switch is outside the loop).
    switch (in.op) {
#define LEVELSET_FORMULA_LOOP(OP) \
  case Op::OP:                     \
    for (int i = 0; i < n; ++i) d[i] = apply<float>(Op::OP, a[i], b[i], e[i]); \
    break;
      LEVELSET_FORMULA_LOOP(Neg) LEVELSET_FORMULA_LOOP(Not) LEVELSET_FORMULA_LOOP(Add) LEVELSET_FORMULA_LOOP(Sub)
      LEVELSET_FORMULA_LOOP(Mul) LEVELSET_FORMULA_LOOP(Div) LEVELSET_FORMULA_LOOP(Pow) LEVELSET_FORMULA_LOOP(Lt)
      LEVELSET_FORMULA_LOOP(Le) LEVELSET_FORMULA_LOOP(Gt) LEVELSET_FORMULA_LOOP(Ge) LEVELSET_FORMULA_LOOP(Eq)
      LEVELSET_FORMULA_LOOP(Ne) LEVELSET_FORMULA_LOOP(And) LEVELSET_FORMULA_LOOP(Or) LEVELSET_FORMULA_LOOP(Select)
      LEVELSET_FORMULA_LOOP(Abs) LEVELSET_FORMULA_LOOP(Sign) LEVELSET_FORMULA_LOOP(Sqrt) LEVELSET_FORMULA_LOOP(Cbrt)
      LEVELSET_FORMULA_LOOP(Exp) LEVELSET_FORMULA_LOOP(Log) LEVELSET_FORMULA_LOOP(Sin) LEVELSET_FORMULA_LOOP(Cos)
      LEVELSET_FORMULA_LOOP(Tan) LEVELSET_FORMULA_LOOP(Asin) LEVELSET_FORMULA_LOOP(Acos) LEVELSET_FORMULA_LOOP(Atan)
      LEVELSET_FORMULA_LOOP(Floor) LEVELSET_FORMULA_LOOP(Ceil) LEVELSET_FORMULA_LOOP(Atan2) LEVELSET_FORMULA_LOOP(Min)
      LEVELSET_FORMULA_LOOP(Max) LEVELSET_FORMULA_LOOP(Step) LEVELSET_FORMULA_LOOP(Clamp)
      LEVELSET_FORMULA_LOOP(Smoothstep)
#undef LEVELSET_FORMULA_LOOP
      case Op::Const:
      case Op::Var: break;
    }
  }
  const float* r = slot(c.result_slot);
  std::copy_n(r, n, out);
}

struct ProgramAccess {
  static void set(Program& p, std::string text, std::uint32_t uses, std::vector<Node> nodes, int root,
                  std::vector<Instruction> code, int registers, int result) {
    p.text_ = std::move(text);
    p.uses_ = uses;
    p.code_->nodes = std::move(nodes);
    p.code_->root = root;
    p.code_->code = std::move(code);
    p.code_->registers = registers;
    p.code_->result_slot = result;
  }
};

namespace {

void check_options(const CompileOptions& options) {
  for (const auto& [name, value] : options.constants) {
    if (!std::isfinite(value))
      throw Error(ErrorCode::InvalidArgument, "formula", "constant '" + name + "' must be finite");
    if (var_from_name(name) != Var::count || find_function(name) || name == "pi")
      throw Error(ErrorCode::InvalidArgument, "formula", "constant '" + name + "' would shadow a built-in name");
    if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_'))
      throw Error(ErrorCode::InvalidArgument, "formula", "constant name '" + name + "' is not an identifier");
  }
}

Program make_program(std::string text, std::vector<Node> nodes, int root, const CompileOptions& options) {
  Program p;
  root = fold(nodes, root);
  std::vector<Instruction> code;
  int registers = 0;
  const int result = emit(nodes, root, code, registers);
  if (int(code.size()) > options.limits.max_instructions)
    throw Error(ErrorCode::LimitExceeded, "formula",
                "compiles to " + std::to_string(code.size()) + " instructions, more than " +
                    std::to_string(options.limits.max_instructions));
  std::uint32_t uses = 0;
  collect_uses(nodes, root, uses);
  ProgramAccess::set(p, std::move(text), uses, std::move(nodes), root, std::move(code), registers, result);
  return p;
}

std::vector<Node> parse(std::string_view text, const CompileOptions& options, int& root) {
  if (text.size() > options.limits.max_length)
    throw Error(ErrorCode::LimitExceeded, "formula",
                "formula of " + std::to_string(text.size()) + " characters, more than " +
                    std::to_string(options.limits.max_length));
  check_options(options);
  std::vector<Node> nodes;
  Parser parser(text, options, nodes);
  root = parser.parse();
  return nodes;
}

}  // namespace

Program compile(std::string_view text, const CompileOptions& options) {
  int root = -1;
  std::vector<Node> nodes = parse(text, options, root);
  return make_program(std::string(text), std::move(nodes), root, options);
}

SplitProgram compile_split_by_curvature(std::string_view text, const CompileOptions& options) {
  int root = -1;
  std::vector<Node> nodes = parse(text, options, root);
  // Terms of the top-level sum, with their signs.
  std::vector<std::pair<int, bool>> terms;  // node, negated
  std::vector<std::pair<int, bool>> stack{{root, false}};
  while (!stack.empty()) {
    const auto [i, neg] = stack.back();
    stack.pop_back();
    const Node& n = nodes[std::size_t(i)];
    if (n.op == Op::Add || n.op == Op::Sub) {
      stack.push_back({n.arg[1], n.op == Op::Sub ? !neg : neg});
      stack.push_back({n.arg[0], neg});
    } else if (n.op == Op::Neg) {
      stack.push_back({n.arg[0], !neg});
    } else {
      terms.push_back({i, neg});
    }
  }
  auto sum_of = [&](bool curvature) {
    int acc = -1;
    for (const auto& [i, neg] : terms) {
      if (reads_curvature(nodes, i) != curvature) continue;
      int term = i;
      if (acc < 0) {
        if (neg) {
          Node m;
          m.op = Op::Neg;
          m.arg = {term, -1, -1};
          m.args = 1;
          nodes.push_back(m);
          term = int(nodes.size()) - 1;
        }
        acc = term;
        continue;
      }
      Node m;
      m.op = neg ? Op::Sub : Op::Add;
      m.arg = {acc, term, -1};
      m.args = 2;
      nodes.push_back(m);
      acc = int(nodes.size()) - 1;
    }
    if (acc < 0) {
      nodes.push_back(Node{});  // the constant 0
      acc = int(nodes.size()) - 1;
    }
    return acc;
  };
  const int plain = sum_of(false), curved = sum_of(true);
  SplitProgram out;
  out.without_curvature = make_program(std::string(text) + " [terms without curvature]", nodes, plain, options);
  out.with_curvature = make_program(std::string(text) + " [curvature terms]", std::move(nodes), curved, options);
  return out;
}

}  // namespace levelset::formula
