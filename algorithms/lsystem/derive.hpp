// Parallel, deterministic rewriting of an LString by a Grammar.
//
// One generation is two passes over fixed blocks of the input (TBB): the first chooses a rule for every
// module and counts what the block will write, an exclusive scan turns the counts into output offsets
// (the total is checked against the symbol limit before anything is allocated), and the second writes
// each block's output at its offset. Blocks never share output, and every random draw is a pure
// function of (seed, stream, generation, module index, rule index), so the string is identical for
// any thread count.
//
// Rule choice. Rules for a symbol are tried in file order; the first applicable rule wins (its
// pattern's parameter count, contexts and condition hold). Probabilities, two documented modes:
//  - sequential (Houdini's wording, the default): an applicable rule with a probability p fires with
//    chance p (an independent draw per rule); if it does not, the next rule is tried. So
//    A=X:0.5, A=Y:0.5 gives X 50%, Y 25%, and A copied 25%.
//  - normalized (The Algorithmic Beauty of Plants): the applicable probabilistic rules before the first
//    applicable rule without a probability form one choice; rule k is picked with chance
//    p_k / max(1, sum p); the rest (1 - sum p when sum p < 1) goes to that rule without a probability,
//    or to copying the symbol. So A=X:0.5, A=Y:0.5 gives X 50%, Y 50%.
// A symbol with no applicable rule is copied.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "algorithms/lsystem/grammar.hpp"
#include "algorithms/lsystem/lstring.hpp"

namespace growbench::lsys {

enum class ProbabilityMode { Sequential, Normalized };
// How a rule's probability reads: Auto, a fraction up to 1 and a percentage above it; Fraction, 0 to 1
// (1 or more: always); Percent, 0 to 100.
enum class ProbabilityUnits { Auto, Fraction, Percent };

// The turtle's state at a module, for rules whose conditions or arguments read x y z A L W U V.
struct TurtleVars {
  float x = 0, y = 0, z = 0, arc = 0, length = 0, width = 0, u = 0, v = 0;
};

// How to rewrite. The values come from the parameter table (make_setup in lsystem.cpp): no member has a
// default of its own.
struct DeriveSettings {
  const ExprHost* host;
  std::uint64_t seed;
  std::uint64_t stream;  // e.g. the plant (scene seed) index
  ProbabilityMode probability;
  ProbabilityUnits units;
  bool brackets_transparent;  // [ or ] in the ignore list: contexts are matched on the flat string
  bool siblings;              // Context Includes Siblings: a right context goes on in the next sibling branch
  bool left_in_branch;        // a left context stops at its branch's start, as a right context at its end
  std::size_t max_symbols;
  std::size_t max_params;
  std::array<double, kMaxSlots> env;  // a b c d T and user variables filled in, the rest 0
};

class Deriver {
 public:
  Deriver(const Grammar& grammar, DeriveSettings settings);

  // The premise, evaluated at generation 0.
  void premise(LString& out) const;
  // Rewrites `in` into `out` as generation `generation` (1 for the first rewrite). `states` holds the
  // turtle state of every module of `in` when the grammar reads it (else may be empty). Throws
  // InputError when the result would exceed the symbol or parameter limit.
  void rewrite(const LString& in, LString& out, int generation, const std::vector<TurtleVars>& states);

  // The random stream of the plant being rewritten (one per scene seed).
  void set_stream(std::uint64_t stream) { s_.stream = stream; }
  [[nodiscard]] const Grammar& grammar() const { return g_; }
  [[nodiscard]] const DeriveSettings& settings() const { return s_; }

 private:
  struct Block;
  int choose(const LString& in, std::size_t m, std::size_t poff, double* env, int generation) const;
  bool bind(const Rule& r, const LString& in, std::size_t m, std::size_t poff, double* env) const;
  [[nodiscard]] bool neighbours_allow(const Rule& r, const LString& in, std::size_t m) const;

  const Grammar& g_;
  DeriveSettings s_;
  // 0 copy; 1 one static rule without conditions; 2 general; 3 one rule without conditions whose pattern
  // names its parameters: it applies exactly to the modules with that many, so nothing is chosen.
  std::uint8_t kind_[128] = {};
  bool has_cut_ = false;      // the premise or a successor holds '%' (cut_branches runs after each rewrite)
  bool any_general_ = false;  // some symbol is kind 2: rule choices are stored per module
  std::uint32_t static_symbols_[128] = {}, static_params_[128] = {};  // output size of a kind-1 or 3 symbol
  std::uint8_t formals_[128] = {};                                    // parameters a kind-3 symbol needs
  bool lone_context_[128] = {};  // a kind-2 symbol whose one rule has a context (checked before choosing)
  std::vector<std::vector<std::uint16_t>> out_words_;  // per rule: its successor's encoded words, flagged new
  std::vector<std::uint16_t> choice_;
  std::vector<std::size_t> block_in_params_, block_out_syms_, block_out_params_;
};

// Symbol counts of a string (index: ASCII code).
std::vector<std::size_t> symbol_counts(const LString& s);

}  // namespace growbench::lsys
