// Expressions of the Houdini L-system dialect, compiled once to a small stack bytecode and evaluated
// per module without re-parsing.
//
// Grammar (lowest precedence first):
//   or      := and (('|' | '||') and)*
//   and     := eq (('&' | '&&') eq)*
//   eq      := rel (('==' | '=' | '!=') rel)*        a lone '=' compares, as in Houdini's ':m=0'
//   rel     := add (('<' | '<=' | '>' | '>=') add)*
//   add     := mul (('+' | '-') mul)*
//   mul     := unary (('*' | '/' | '%') unary)*
//   unary   := ('-' | '+' | '!') unary | power
//   power   := primary ('^' unary)?                     right-associative
//   primary := number | name | name '(' args ')' | '(' or ')'
// Truth is "not zero"; comparisons and logic give 1 or 0. Angles of sin, cos, tan, asin, acos, atan2
// are in degrees (the reference's convention).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace growbench::lsys {

// Where each variable lives in the evaluation environment (a flat array of doubles).
enum Slot : std::uint8_t {
  kFormal0 = 0,  // rule formals: predecessor and context parameters, up to kMaxFormals
  kMaxFormals = 24,
  kVarA = kMaxFormals,  // a: angle
  kVarB,
  kVarC,
  kVarD,
  kVarAge,         // g
  kVarIndex,       // i
  kVarGeneration,  // t
  kVarX,
  kVarY,
  kVarZ,
  kVarArc,      // A
  kVarLength,   // L
  kVarGravity,  // T
  kVarU,
  kVarV,      // colour indices
  kVarWidth,  // W
  kUserVar0,  // user-defined single-letter variables follow
  kMaxSlots = 96,
};

// Calls an expression can make that need the outside world (the scene, an image, the seed).
class ExprHost {
 public:
  virtual ~ExprHost() = default;
  virtual double in(double x, double y, double z) const = 0;
  virtual double pic(double u, double v, double plane) const = 0;
  virtual double rand(double seed) const = 0;
  virtual double chan(double index) const = 0;
};

enum class Op : std::uint8_t {
  Const,
  Load,
  Add,
  Sub,
  Mul,
  Div,
  Mod,
  Pow,
  Neg,
  Not,
  Lt,
  Le,
  Gt,
  Ge,
  Eq,
  Ne,
  And,
  Or,
  Sin,
  Cos,
  Tan,
  Asin,
  Acos,
  Atan,
  Atan2,
  Sqrt,
  Abs,
  Floor,
  Ceil,
  Min,
  Max,
  Clamp,
  Rand,
  In,
  Pic,
  Chan,
};

struct Instr {
  Op op;
  std::uint8_t slot = 0;
  double value = 0.0;
};

// Which environment slots an expression reads (bit i = slot i) and which host calls it makes.
struct ExprUse {
  std::uint64_t formals = 0;  // bit per formal slot
  bool turtle = false;        // x y z A L W U V or in()/pic() of them: needs the turtle's state
  bool age = false;           // g
};

// The largest magnitude a module's parameter holds: the parameters are 32-bit floats.
inline constexpr double kMaxModuleParameter = std::numeric_limits<float>::max();

class Expr {
 public:
  Expr() = default;
  // The value. A value that is not finite (a division by zero, an overflow), or beyond a 32-bit float
  // for an expression whose value becomes a module's parameter, is an InputError naming the origin and
  // the operation that made it (see set_origin).
  [[nodiscard]] double eval(const double* env, const ExprHost& host) const {
    const double v = value(env, host);
    if (!std::isfinite(v) || (module_parameter_ && std::abs(v) > kMaxModuleParameter)) [[unlikely]]
      fail_eval(env, host, v);
    return v;
  }
  // What eval's errors name: "FILE:LINE:COL: in rule '...': the condition 'x/y'". `module_parameter`:
  // the value is stored as a module's parameter, a 32-bit float.
  void set_origin(std::string origin, bool module_parameter);
  [[nodiscard]] bool empty() const { return code_.empty(); }
  [[nodiscard]] bool constant() const { return code_.size() == 1 && code_[0].op == Op::Const; }
  [[nodiscard]] double constant_value() const { return code_[0].value; }
  [[nodiscard]] const ExprUse& use() const { return use_; }
  [[nodiscard]] const std::string& text() const { return text_; }

 private:
  friend class ExprCompiler;
  // Most arguments in practice are a constant, a variable, or a variable and a constant under one
  // arithmetic operation (l*0.9, i+1). Those shapes skip the stack machine; the operation and its
  // operand order are the bytecode's, so the value is the same to the bit.
  enum class Shape : std::uint8_t { General, Constant, Variable, VariableOpConstant, ConstantOpVariable };
  [[nodiscard]] double value(const double* env, const ExprHost& host) const {
    switch (shape_) {
      case Shape::Constant:
        return shape_value_;
      case Shape::Variable:
        return env[shape_slot_];
      case Shape::VariableOpConstant:
        return arith(shape_op_, env[shape_slot_], shape_value_);
      case Shape::ConstantOpVariable:
        return arith(shape_op_, shape_value_, env[shape_slot_]);
      default:
        return run(env, host);
    }
  }
  static double arith(Op op, double a, double b) {
    switch (op) {
      case Op::Add:
        return a + b;
      case Op::Sub:
        return a - b;
      case Op::Mul:
        return a * b;
      default:
        return a / b;
    }
  }
  void classify();
  [[nodiscard]] double run(const double* env, const ExprHost& host) const;
  // Which operation first made a value that is not finite, for messages ("a division by zero").
  [[nodiscard]] std::string diagnose(const double* env, const ExprHost& host) const;
  [[noreturn]] void fail_eval(const double* env, const ExprHost& host, double value) const;
  std::vector<Instr> code_;
  ExprUse use_;
  std::string text_;
  std::string origin_;
  bool module_parameter_ = false;
  Shape shape_ = Shape::General;
  Op shape_op_ = Op::Add;
  std::uint8_t shape_slot_ = 0;
  double shape_value_ = 0.0;
};

// A compile error: `offset` is the byte offset into the expression text where the problem is.
struct ExprError {
  std::size_t offset;
  std::string message;
};

// Name resolution for one rule: its formal parameter names, then the reserved single-letter variables,
// then the user's variables (`user_names[k]` lives in slot kUserVar0 + k).
struct ExprScope {
  const std::vector<std::string>* formals = nullptr;
  const std::vector<std::string>* user_names = nullptr;
};

class ExprCompiler {
 public:
  // Compiles `text`; on error returns false and fills `error`. Constant sub-expressions are folded.
  static bool compile(std::string_view text, const ExprScope& scope, Expr& out, ExprError& error);
};

// Reserved single-letter variables and their slots ("a" -> kVarA, ...); -1 when not reserved.
int reserved_slot(std::string_view name);

}  // namespace growbench::lsys
