// The formula parser (formula_internal.hpp): recursive descent over the text, a tree of Nodes.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>

#include "core/error.hpp"
#include "core/suggest.hpp"
#include "core/text.hpp"
#include "formula/formula_internal.hpp"

namespace levelset::formula::detail {

namespace {

[[noreturn]] void fail(std::string_view text, int column, const std::string& message, ErrorCode code = ErrorCode::ParseError) {
  std::string caret(std::size_t(std::max(0, column - 1)), ' ');
  caret += '^';
  throw Error(code, "formula:column " + std::to_string(column), message + "\n  " + std::string(text) + "\n  " + caret);
}


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
    static constexpr std::string_view kTwo[] = {"<=", ">=", "==", "!=", "&&", "||"};
    for (const std::string_view two : kTwo)
      if (text_.substr(pos_, 2) == two) {
        tok_.kind = Token::Sym;
        tok_.text = std::string(two);
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

}  // namespace

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

}  // namespace levelset::formula::detail
