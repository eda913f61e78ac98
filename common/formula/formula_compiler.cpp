// The formula compiler (formula_internal.hpp): constant folding, fused register code, and
// compile() / compile_split_by_curvature().
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "formula/formula_internal.hpp"

namespace levelset::formula {

using namespace detail;

namespace detail {

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

}  // namespace detail

namespace {

// Slots: [0, kVarCount) input variables, kVarCount + r register r.

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

static Program make_program(std::string text, std::vector<Node> nodes, int root, const CompileOptions& options) {
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
