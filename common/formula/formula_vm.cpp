// Program (formula.hpp): the scalar reference and the vectorised loops over up to 512 samples,
// one tight loop per instruction (formula_internal.hpp).
#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "formula/formula_internal.hpp"

namespace levelset::formula {

using namespace detail;

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

}  // namespace levelset::formula
