#include "algorithms/lsystem/expr.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/utf8.hpp"

namespace growbench::lsys {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kMaxStack = 64;

// A value for a message: "nan" whatever its sign bit (sqrt(-1) gives -nan), else the shortest %g.
std::string shown(double v) {
  return std::isnan(v) ? "nan" : fmt::format("{:g}", v);
}
// Nesting the recursive-descent parser follows, bounded so that no input runs it off the stack.
constexpr int kMaxDepth = 200;

struct Function {
  const char* name;
  Op op;
  int arity;
  bool host;
};
constexpr Function kFunctions[] = {
    {"sin", Op::Sin, 1, false},     {"cos", Op::Cos, 1, false},     {"tan", Op::Tan, 1, false},
    {"asin", Op::Asin, 1, false},   {"acos", Op::Acos, 1, false},   {"atan", Op::Atan, 1, false},
    {"atan2", Op::Atan2, 2, false}, {"sqrt", Op::Sqrt, 1, false},   {"abs", Op::Abs, 1, false},
    {"floor", Op::Floor, 1, false}, {"ceil", Op::Ceil, 1, false},   {"min", Op::Min, 2, false},
    {"max", Op::Max, 2, false},     {"clamp", Op::Clamp, 3, false}, {"pow", Op::Pow, 2, false},
    {"rand", Op::Rand, 1, true},    {"in", Op::In, 3, true},        {"pic", Op::Pic, 3, true},
    {"chan", Op::Chan, 1, true},
};

struct Reserved {
  const char* name;
  int slot;
  bool turtle;
};
constexpr Reserved kReserved[] = {
    {"a", kVarA, false},       {"b", kVarB, false},     {"c", kVarC, false},          {"d", kVarD, false},
    {"g", kVarAge, false},     {"i", kVarIndex, false}, {"t", kVarGeneration, false}, {"x", kVarX, true},
    {"y", kVarY, true},        {"z", kVarZ, true},      {"A", kVarArc, true},         {"L", kVarLength, true},
    {"T", kVarGravity, false}, {"U", kVarU, true},      {"V", kVarV, true},           {"W", kVarWidth, true},
};

int stack_effect(Op op) {
  switch (op) {
    case Op::Const:
    case Op::Load:
      return 1;
    case Op::Neg:
    case Op::Not:
    case Op::Sin:
    case Op::Cos:
    case Op::Tan:
    case Op::Asin:
    case Op::Acos:
    case Op::Atan:
    case Op::Sqrt:
    case Op::Abs:
    case Op::Floor:
    case Op::Ceil:
    case Op::Rand:
    case Op::Chan:
      return 0;
    case Op::In:
    case Op::Pic:
    case Op::Clamp:
      return -2;
    default:
      return -1;  // binary operators
  }
}

class Parser {
 public:
  Parser(std::string_view text, const ExprScope& scope, std::vector<Instr>& code, ExprUse& use)
      : s_(text), scope_(scope), code_(code), use_(use) {}

  bool run(ExprError& error) {
    try {
      skip();
      if (pos_ >= s_.size()) fail("expected an expression");
      parse_or();
      skip();
      if (pos_ < s_.size()) fail(fmt::format("unexpected '{}' after the expression", utf8_char_at(s_, pos_)));
      return true;
    } catch (const ExprError& e) {
      error = e;
      return false;
    }
  }

 private:
  [[noreturn]] void fail(std::string message) const { throw ExprError{pos_, std::move(message)}; }
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool peek(std::string_view tok) {
    skip();
    return s_.substr(pos_, tok.size()) == tok;
  }
  bool accept(std::string_view tok) {
    if (!peek(tok)) return false;
    pos_ += tok.size();
    return true;
  }
  void emit(Op op, std::uint8_t slot = 0, double value = 0.0) { code_.push_back({op, slot, value}); }

  void parse_or() {
    parse_and();
    while (true) {
      if (accept("||") || accept("|")) {
        parse_and();
        emit(Op::Or);
      } else {
        return;
      }
    }
  }
  void parse_and() {
    parse_eq();
    while (true) {
      if (accept("&&") || accept("&")) {
        parse_eq();
        emit(Op::And);
      } else {
        return;
      }
    }
  }
  void parse_eq() {
    parse_rel();
    while (true) {
      if (accept("==")) {
        parse_rel();
        emit(Op::Eq);
      } else if (accept("!=")) {
        parse_rel();
        emit(Op::Ne);
      } else if (accept("=")) {
        parse_rel();
        emit(Op::Eq);
      } else {
        return;
      }
    }
  }
  void parse_rel() {
    parse_add();
    while (true) {
      if (accept("<=")) {
        parse_add();
        emit(Op::Le);
      } else if (accept(">=")) {
        parse_add();
        emit(Op::Ge);
      } else if (accept("<")) {
        parse_add();
        emit(Op::Lt);
      } else if (accept(">")) {
        parse_add();
        emit(Op::Gt);
      } else {
        return;
      }
    }
  }
  void parse_add() {
    parse_mul();
    while (true) {
      if (accept("+")) {
        parse_mul();
        emit(Op::Add);
      } else if (accept("-")) {
        parse_mul();
        emit(Op::Sub);
      } else {
        return;
      }
    }
  }
  void parse_mul() {
    parse_unary();
    while (true) {
      if (accept("*")) {
        parse_unary();
        emit(Op::Mul);
      } else if (accept("/")) {
        parse_unary();
        emit(Op::Div);
      } else if (accept("%")) {
        parse_unary();
        emit(Op::Mod);
      } else {
        return;
      }
    }
  }
  void parse_unary() {
    if (++depth_ > kMaxDepth)
      fail(fmt::format("expression nested more than {} deep (parentheses, unary operators, powers and calls)",
                       kMaxDepth));
    if (accept("-")) {
      parse_unary();
      emit(Op::Neg);
    } else if (accept("+")) {
      parse_unary();
    } else if (peek("!") && !peek("!=")) {
      ++pos_;
      parse_unary();
      emit(Op::Not);
    } else {
      parse_primary();
      if (accept("^")) {
        parse_unary();
        emit(Op::Pow);
      }
    }
    --depth_;
  }
  void parse_primary() {
    skip();
    if (pos_ >= s_.size()) fail("expected a number, a variable, a function call or '('");
    const char ch = s_[pos_];
    if (ch == '(') {
      ++pos_;
      parse_or();
      if (!accept(")")) fail("expected ')'");
      return;
    }
    if (std::isdigit(static_cast<unsigned char>(ch)) || ch == '.') {
      const std::size_t start = pos_;
      while (pos_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '.' ||
                                  ((s_[pos_] == 'e' || s_[pos_] == 'E') && pos_ + 1 < s_.size() &&
                                   (std::isdigit(static_cast<unsigned char>(s_[pos_ + 1])) ||
                                    ((s_[pos_ + 1] == '-' || s_[pos_ + 1] == '+') && pos_ + 2 < s_.size() &&
                                     std::isdigit(static_cast<unsigned char>(s_[pos_ + 2]))))))) {
        if (s_[pos_] == 'e' || s_[pos_] == 'E') ++pos_;  // the exponent sign (if any) follows
        ++pos_;
      }
      double v = 0.0;
      const std::string_view number = s_.substr(start, pos_ - start);
      const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), v);
      if (ec == std::errc::result_out_of_range) {
        pos_ = start;
        fail(fmt::format("number '{}' is out of range; expected a magnitude from {:g} to {:g}, or 0", number,
                         std::numeric_limits<double>::min(), std::numeric_limits<double>::max()));
      }
      if (ec != std::errc() || end != number.data() + number.size()) {
        pos_ = start;
        fail(fmt::format("malformed number '{}'", number));
      }
      emit(Op::Const, 0, v);
      return;
    }
    if (std::isalpha(static_cast<unsigned char>(ch)) || ch == '_') {
      const std::size_t start = pos_;
      while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_')) ++pos_;
      const std::string_view name = s_.substr(start, pos_ - start);
      skip();
      if (pos_ < s_.size() && s_[pos_] == '(') {
        for (const auto& f : kFunctions) {
          if (name != f.name) continue;
          ++pos_;
          for (int k = 0; k < f.arity; ++k) {
            if (k > 0 && !accept(",")) fail(fmt::format("{}() takes {} arguments; expected ','", f.name, f.arity));
            parse_or();
          }
          if (!accept(")"))
            fail(fmt::format("{}() takes {} argument{}; expected ')'", f.name, f.arity, f.arity == 1 ? "" : "s"));
          emit(f.op);
          if (f.op == Op::In || f.op == Op::Pic) use_.turtle = true;
          return;
        }
        pos_ = start;
        fail(fmt::format("unknown function '{}'", name));
      }
      load(name, start);
      return;
    }
    fail(fmt::format("expected a number, a variable, a function call or '(', found '{}'", utf8_char_at(s_, pos_)));
  }
  void load(std::string_view name, std::size_t at) {
    if (scope_.formals) {
      for (std::size_t k = 0; k < scope_.formals->size(); ++k) {
        if ((*scope_.formals)[k] == name) {
          emit(Op::Load, static_cast<std::uint8_t>(kFormal0 + k));
          use_.formals |= 1ull << k;
          return;
        }
      }
    }
    for (const auto& r : kReserved) {
      if (name == r.name) {
        emit(Op::Load, static_cast<std::uint8_t>(r.slot));
        if (r.turtle) use_.turtle = true;
        if (r.slot == kVarAge) use_.age = true;
        return;
      }
    }
    if (scope_.user_names) {
      for (std::size_t k = 0; k < scope_.user_names->size(); ++k) {
        if ((*scope_.user_names)[k] == name) {
          emit(Op::Load, static_cast<std::uint8_t>(kUserVar0 + k));
          return;
        }
      }
    }
    pos_ = at;
    fail(
        fmt::format("unknown variable '{}' (not a parameter of this rule, a reserved variable "
                    "a b c d g i t x y z A L T U V W, or a user variable)",
                    name));
  }

  std::string_view s_;
  const ExprScope& scope_;
  std::vector<Instr>& code_;
  ExprUse& use_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

int reserved_slot(std::string_view name) {
  for (const auto& r : kReserved)
    if (name == r.name) return r.slot;
  return -1;
}

bool ExprCompiler::compile(std::string_view text, const ExprScope& scope, Expr& out, ExprError& error) {
  out = Expr();
  out.text_ = std::string(text);
  Parser p(text, scope, out.code_, out.use_);
  if (!p.run(error)) return false;
  int depth = 0, max_depth = 0;
  for (const auto& in : out.code_) {
    depth += stack_effect(in.op);
    max_depth = std::max(max_depth, depth);
  }
  if (max_depth > kMaxStack) {
    error = {0, fmt::format("expression needs a stack of {} values; at most {} are supported", max_depth, kMaxStack)};
    return false;
  }
  bool pure = out.code_.size() > 1;
  for (const auto& in : out.code_)
    if (in.op == Op::Load || in.op == Op::Rand || in.op == Op::In || in.op == Op::Pic || in.op == Op::Chan)
      pure = false;
  if (pure) {
    struct NoHost final : ExprHost {
      double in(double, double, double) const override { return 0.0; }
      double pic(double, double, double) const override { return 0.0; }
      double rand(double) const override { return 0.0; }
      double chan(double) const override { return 0.0; }
    } host;
    const double v = out.run(nullptr, host);
    if (!std::isfinite(v)) {
      error = {0, fmt::format("the expression is always {}, from {}", shown(v), out.diagnose(nullptr, host))};
      return false;
    }
    out.code_.assign(1, Instr{Op::Const, 0, v});
  }
  out.classify();
  return true;
}

void Expr::set_origin(std::string origin, bool module_parameter) {
  origin_ = std::move(origin);
  module_parameter_ = module_parameter;
}

void Expr::classify() {
  shape_ = Shape::General;
  const auto arithmetic = [](Op op) { return op == Op::Add || op == Op::Sub || op == Op::Mul || op == Op::Div; };
  if (code_.size() == 1 && code_[0].op == Op::Const) {
    shape_ = Shape::Constant;
    shape_value_ = code_[0].value;
  } else if (code_.size() == 1 && code_[0].op == Op::Load) {
    shape_ = Shape::Variable;
    shape_slot_ = code_[0].slot;
  } else if (code_.size() == 3 && arithmetic(code_[2].op)) {
    shape_op_ = code_[2].op;
    if (code_[0].op == Op::Load && code_[1].op == Op::Const) {
      shape_ = Shape::VariableOpConstant;
      shape_slot_ = code_[0].slot;
      shape_value_ = code_[1].value;
    } else if (code_[0].op == Op::Const && code_[1].op == Op::Load) {
      shape_ = Shape::ConstantOpVariable;
      shape_slot_ = code_[1].slot;
      shape_value_ = code_[0].value;
    }
  }
}

void Expr::fail_eval(const double* env, const ExprHost& host, double value) const {
  const std::string cause =
      std::isfinite(value)
          ? fmt::format("beyond the largest module parameter, {:g} (a 32-bit float)", kMaxModuleParameter)
          : fmt::format("from {}", diagnose(env, host));
  throw InputError(
      fmt::format("{} gave {}, {}", origin_.empty() ? fmt::format("'{}'", text_) : origin_, shown(value), cause));
}

namespace {

// One instruction on the stack st (sp values). Inlined into both loops below: the evaluation's, and the
// diagnosis's, which checks every step.
[[gnu::always_inline]] inline void exec(const Instr& in, double* st, int& sp, const double* env, const ExprHost& host) {
  switch (in.op) {
    case Op::Const:
      st[sp++] = in.value;
      break;
    case Op::Load:
      st[sp++] = env[in.slot];
      break;
    case Op::Add:
      --sp;
      st[sp - 1] += st[sp];
      break;
    case Op::Sub:
      --sp;
      st[sp - 1] -= st[sp];
      break;
    case Op::Mul:
      --sp;
      st[sp - 1] *= st[sp];
      break;
    case Op::Div:
      --sp;
      st[sp - 1] /= st[sp];
      break;
    case Op::Mod:
      --sp;
      st[sp - 1] = std::fmod(st[sp - 1], st[sp]);
      break;
    case Op::Pow:
      --sp;
      st[sp - 1] = std::pow(st[sp - 1], st[sp]);
      break;
    case Op::Neg:
      st[sp - 1] = -st[sp - 1];
      break;
    case Op::Not:
      st[sp - 1] = st[sp - 1] == 0.0 ? 1.0 : 0.0;
      break;
    case Op::Lt:
      --sp;
      st[sp - 1] = st[sp - 1] < st[sp] ? 1.0 : 0.0;
      break;
    case Op::Le:
      --sp;
      st[sp - 1] = st[sp - 1] <= st[sp] ? 1.0 : 0.0;
      break;
    case Op::Gt:
      --sp;
      st[sp - 1] = st[sp - 1] > st[sp] ? 1.0 : 0.0;
      break;
    case Op::Ge:
      --sp;
      st[sp - 1] = st[sp - 1] >= st[sp] ? 1.0 : 0.0;
      break;
    case Op::Eq:
      --sp;
      st[sp - 1] = st[sp - 1] == st[sp] ? 1.0 : 0.0;
      break;
    case Op::Ne:
      --sp;
      st[sp - 1] = st[sp - 1] != st[sp] ? 1.0 : 0.0;
      break;
    case Op::And:
      --sp;
      st[sp - 1] = (st[sp - 1] != 0.0 && st[sp] != 0.0) ? 1.0 : 0.0;
      break;
    case Op::Or:
      --sp;
      st[sp - 1] = (st[sp - 1] != 0.0 || st[sp] != 0.0) ? 1.0 : 0.0;
      break;
    case Op::Sin:
      st[sp - 1] = std::sin(st[sp - 1] * kDeg);
      break;
    case Op::Cos:
      st[sp - 1] = std::cos(st[sp - 1] * kDeg);
      break;
    case Op::Tan:
      st[sp - 1] = std::tan(st[sp - 1] * kDeg);
      break;
    case Op::Asin:
      st[sp - 1] = std::asin(std::clamp(st[sp - 1], -1.0, 1.0)) / kDeg;
      break;
    case Op::Acos:
      st[sp - 1] = std::acos(std::clamp(st[sp - 1], -1.0, 1.0)) / kDeg;
      break;
    case Op::Atan:
      st[sp - 1] = std::atan(st[sp - 1]) / kDeg;
      break;
    case Op::Atan2:
      --sp;
      st[sp - 1] = std::atan2(st[sp - 1], st[sp]) / kDeg;
      break;
    case Op::Sqrt:
      st[sp - 1] = std::sqrt(st[sp - 1]);
      break;
    case Op::Abs:
      st[sp - 1] = std::fabs(st[sp - 1]);
      break;
    case Op::Floor:
      st[sp - 1] = std::floor(st[sp - 1]);
      break;
    case Op::Ceil:
      st[sp - 1] = std::ceil(st[sp - 1]);
      break;
    case Op::Min:
      --sp;
      st[sp - 1] = std::min(st[sp - 1], st[sp]);
      break;
    case Op::Max:
      --sp;
      st[sp - 1] = std::max(st[sp - 1], st[sp]);
      break;
    case Op::Clamp:
      sp -= 2;
      st[sp - 1] = std::clamp(st[sp - 1], std::min(st[sp], st[sp + 1]), std::max(st[sp], st[sp + 1]));
      break;
    case Op::Rand:
      st[sp - 1] = host.rand(st[sp - 1]);
      break;
    case Op::Chan:
      st[sp - 1] = host.chan(st[sp - 1]);
      break;
    case Op::In:
      sp -= 2;
      st[sp - 1] = host.in(st[sp - 1], st[sp], st[sp + 1]);
      break;
    case Op::Pic:
      sp -= 2;
      st[sp - 1] = host.pic(st[sp - 1], st[sp], st[sp + 1]);
      break;
  }
}

std::string describe(Op op, const double* args, int n) {
  auto finite_args = [&] {
    for (int k = 0; k < n; ++k)
      if (!std::isfinite(args[k])) return false;
    return true;
  };
  if (!finite_args()) return "a value that was not finite";
  switch (op) {
    case Op::Div:
      return args[1] == 0.0 ? "a division by zero" : "an overflow in '/'";
    case Op::Mod:
      return "a remainder (%) of a division by zero";
    case Op::Mul:
      return "an overflow in '*'";
    case Op::Add:
    case Op::Sub:
      return "an overflow in '+' or '-'";
    case Op::Pow:
      return args[0] < 0.0 ? "a negative number to a fractional power (^ or pow)" : "an overflow in '^' or pow()";
    case Op::Sqrt:
      return "the square root of a negative number";
    case Op::Tan:
      return "tan() at an odd multiple of 90 degrees";
    case Op::Load:
      return "a variable that was not finite";
    default:
      return "a function's result that was not finite";
  }
}

}  // namespace

double Expr::run(const double* env, const ExprHost& host) const {
  double st[kMaxStack];
  int sp = 0;
  for (const Instr& in : code_) exec(in, st, sp, env, host);
  return st[0];
}

std::string Expr::diagnose(const double* env, const ExprHost& host) const {
  double st[kMaxStack];
  int sp = 0;
  for (const Instr& in : code_) {
    // The operands, as they were before the instruction consumed them.
    const int n = std::max(0, 1 - stack_effect(in.op));
    double args[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < std::min(n, 3); ++k) args[k] = st[sp - n + k];
    exec(in, st, sp, env, host);
    if (!std::isfinite(st[sp - 1])) return describe(in.op, args, n);
  }
  return "an operation";
}

}  // namespace growbench::lsys
