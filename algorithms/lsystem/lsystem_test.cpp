// The L-system: exact derivations from The Algorithmic Beauty of Plants (chapter 1) and the Houdini
// reference, turtle geometry with known answers, probabilities, errors, determinism.
#include <cmath>
#include <map>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "algorithms/grow_util.hpp"
#include "algorithms/lsystem/derive.hpp"
#include "algorithms/lsystem/expr.hpp"
#include "algorithms/lsystem/lsystem.hpp"
#include "algorithms/organ_shapes.hpp"
#include "core/errors.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

Params lsys_params(const std::string& premise, const std::string& rules, double generations,
                   const std::vector<std::string>& extra = {}) {
  Params p = default_params(find_algorithm("lsystem"));
  p.set("premise", premise);
  p.set("rules", rules);
  p.set("generations", std::to_string(generations));
  for (const auto& e : extra) p.set_assignment(e);
  return p;
}

std::string derive(const std::string& premise, const std::string& rules, double generations,
                   const std::vector<std::string>& extra = {}) {
  return derive_lsystem(lsys_params(premise, rules, generations, extra), 1, nullptr, nullptr, 0).text;
}

std::map<char, std::size_t> counts(const DerivedString& d) {
  return {d.counts.begin(), d.counts.end()};
}

// ---------- derivations: The Algorithmic Beauty of Plants, chapter 1 ----------

TEST(LSystemDerivation, AlgaeFibonacci) {  // ABOP 1.1: a -> ab, b -> a
  EXPECT_EQ(derive("b", "a = ab\nb = a", 5), "abaababa");
  const auto d = derive_lsystem(lsys_params("b", "a -> ab\nb -> a", 20), 1, nullptr, nullptr, 0);
  EXPECT_EQ(d.modules, 10946u);  // Fibonacci(21)
  EXPECT_EQ(counts(d)['a'], 6765u);
  EXPECT_EQ(counts(d)['b'], 4181u);
}

TEST(LSystemDerivation, KochIslandCounts) {  // ABOP fig. 1.7a: F-F-F-F, F -> F-F+F+FF-F-F+F
  const std::string rule = "F = F-F+F+FF-F-F+F";
  EXPECT_EQ(derive("F-F-F-F", rule, 1), "F-F+F+FF-F-F+F-F-F+F+FF-F-F+F-F-F+F+FF-F-F+F-F-F+F+FF-F-F+F");
  for (int n = 0; n <= 4; ++n) {
    const auto d = derive_lsystem(lsys_params("F-F-F-F", rule, n), 1, nullptr, nullptr, 0);
    const std::size_t f = 4 * static_cast<std::size_t>(std::pow(8, n));
    const std::size_t turns = 3 + 6 * (f - 4) / 7;  // 3 + 6 * (F_0 + ... + F_{n-1})
    EXPECT_EQ(counts(d)['F'], f) << n;
    EXPECT_EQ(d.modules, f + turns) << n;
  }
}

TEST(LSystemDerivation, BracketedPlantCounts) {  // ABOP fig. 1.24a: F -> F[+F]F[-F]F
  const auto d = derive_lsystem(lsys_params("F", "F=F[+F]F[-F]F", 5), 1, nullptr, nullptr, 0);
  EXPECT_EQ(counts(d)['F'], 3125u);
  EXPECT_EQ(d.modules, 1u + 10u * (3125u - 1u) / 4u);  // each F adds 10 symbols
  EXPECT_EQ(counts(d)['['], counts(d)[']']);
  EXPECT_EQ(derive("F", "F=F[+F]F[-F]F", 1), "F[+F]F[-F]F");
}

TEST(LSystemDerivation, NodeRewriting) {  // ABOP fig. 1.24d: X -> F[+X]F[-X]+X, F -> FF
  EXPECT_EQ(derive("X", "X=F[+X]F[-X]+X\nF=FF", 2), "FF[+F[+X]F[-X]+X]FF[-F[+X]F[-X]+X]+F[+X]F[-X]+X");
  const auto d = derive_lsystem(lsys_params("X", "X=F[+X]F[-X]+X\nF=FF", 7), 1, nullptr, nullptr, 0);
  EXPECT_EQ(counts(d)['X'], 2187u);  // 3^7
  // F count f_n = 2 f_{n-1} + 2 x_{n-1}: 0, 2, 10, 38, 130, 422, 1330, 4118
  EXPECT_EQ(counts(d)['F'], 4118u);
}

TEST(LSystemDerivation, ContextSensitiveSignal) {  // ABOP 1.8: b < a -> b, b -> a
  EXPECT_EQ(derive("baaaaaaaa", "b < a = b\nb = a", 1), "abaaaaaaa");
  EXPECT_EQ(derive("baaaaaaaa", "b < a = b\nb = a", 3), "aaabaaaaa");
  EXPECT_EQ(derive("aaaaaaaab", "a > b = b\nb = a", 2), "aaaaaabaa");
}

TEST(LSystemDerivation, BranchAwareContext) {
  // ABOP section 1.8: BC < S > G[H]M matches S in ABC[DE][SG[HI[JK]L]MNO]
  EXPECT_EQ(derive("ABC[DE][SG[HI[JK]L]MNO]", "BC < S > G[H]M = X", 1), "ABC[DE][XG[HI[JK]L]MNO]");
  // the reference: with A > B = F, A[B] does not resolve (B is in a sub-branch), A[Q]B does
  EXPECT_EQ(derive("A[B]", "A > B = F", 1), "A[B]");
  EXPECT_EQ(derive("A[Q]B", "A > B = F", 1), "F[Q]B");
  // ... and with [ ] in the ignore list it is the other way round
  EXPECT_EQ(derive("A[B]", "A > B = F", 1, {"context_ignore=[]"}), "F[B]");
  EXPECT_EQ(derive("A[Q]B", "A > B = F", 1, {"context_ignore=[]"}), "A[Q]B");
  // left context passes into the parent and over sibling branches
  EXPECT_EQ(derive("B[A]", "B < A = X", 1), "B[X]");
  EXPECT_EQ(derive("B[C]A", "B < A = X", 1), "B[C]X");
  EXPECT_EQ(derive("BCA", "B < A = X", 1), "BCA");
  EXPECT_EQ(derive("BCA", "B < A = X", 1, {"context_ignore=C"}), "BCX");
  // left_context=branch: it stops at its branch's start, as a right context stops at its end; sibling
  // branches before it in its own branch are still skipped
  EXPECT_EQ(derive("B[A]", "B < A = X", 1, {"left_context=branch"}), "B[A]");
  EXPECT_EQ(derive("B[C]A", "B < A = X", 1, {"left_context=branch"}), "B[C]X");
  EXPECT_EQ(derive("[BA]", "B < A = X", 1, {"left_context=branch"}), "[BX]");
  EXPECT_EQ(derive("B[A]", "B < A = X", 1, {"left_context=branch", "context_ignore=[]"}), "B[X]");
  // context parameters bind
  EXPECT_EQ(derive("B(2)A(3)C(4)", "B(x) < A(y) > C(z) : x + z > y = A(x*y*z)", 1), "B(2)A(24)C(4)");
}

// The reference's "Context Includes Siblings" paragraph, rule A>B=F, case by case: by default a right
// context skips sub-branches ([Q]) and stops at its branch's end; [] in context_ignore matches on the
// flat string; the siblings flag lets a context that reaches its branch's end go on in the next sibling
// branch, skipping the parent's own symbols ([A]Q[B] resolves). With [] ignored there are no branches
// left for the flag to act on.
TEST(LSystemDerivation, ContextIncludesSiblings) {
  const std::string rule = "A > B = F";
  const std::vector<std::string> siblings = {"context_siblings=true"};
  const std::vector<std::string> flat = {"context_ignore=[]"};
  const std::vector<std::string> both = {"context_siblings=true", "context_ignore=[]"};
  // A[B]: B is in a sub-branch
  EXPECT_EQ(derive("A[B]", rule, 1), "A[B]");
  EXPECT_EQ(derive("A[B]", rule, 1, flat), "F[B]");
  EXPECT_EQ(derive("A[B]", rule, 1, siblings), "A[B]");
  EXPECT_EQ(derive("A[B]", rule, 1, both), "F[B]");
  // A[Q]B: the sub-branch [Q] is skipped
  EXPECT_EQ(derive("A[Q]B", rule, 1), "F[Q]B");
  EXPECT_EQ(derive("A[Q]B", rule, 1, flat), "A[Q]B");
  EXPECT_EQ(derive("A[Q]B", rule, 1, siblings), "F[Q]B");
  EXPECT_EQ(derive("A[Q]B", rule, 1, both), "A[Q]B");
  // [A]Q[B]: B is in the sibling branch after A's
  EXPECT_EQ(derive("[A]Q[B]", rule, 1), "[A]Q[B]");
  EXPECT_EQ(derive("[A]Q[B]", rule, 1, flat), "[A]Q[B]");
  EXPECT_EQ(derive("[A]Q[B]", rule, 1, siblings), "[F]Q[B]");
  EXPECT_EQ(derive("[A]Q[B]", rule, 1, both), "[A]Q[B]");
  // only the next sibling, from its start (its own sub-branches skipped), and only within the parent
  EXPECT_EQ(derive("[A]Q[C][B]", rule, 1, siblings), "[A]Q[C][B]");
  EXPECT_EQ(derive("[A]Q[[C]B]", rule, 1, siblings), "[F]Q[[C]B]");
  EXPECT_EQ(derive("[[A]Q]R[B]", rule, 1, siblings), "[[A]Q]R[B]");
  EXPECT_EQ(derive("[A]Q[B]", "A > BC = F", 1, siblings), "[A]Q[B]");
  EXPECT_EQ(derive("[A]Q[BC]", "A > BC = F", 1, siblings), "[F]Q[BC]");
  // parameters bind across the parent's symbols
  EXPECT_EQ(derive("[A]Q(5)[B(2)]", "A > B(x) = F(x)", 1, siblings), "[F(2)]Q(5)[B(2)]");
  // the left context is the same either way (ABOP's: into the parent, over sibling branches)
  EXPECT_EQ(derive("B[C]A", "B < A = X", 1, siblings), "B[C]X");
  EXPECT_EQ(derive("[A]Q[B]", "Q < B = X", 1, siblings), "[A]Q[X]");
}

TEST(LSystemDerivation, Parametric) {  // ABOP 1.10, fig. 1.31
  const std::string rules =
      "A(x,y): y <= 3 = A(x*2, x+y)\n"
      "A(x,y): y > 3 = B(x)A(x/y, 0)\n"
      "B(x): x < 1 = C\n"
      "B(x): x >= 1 = B(x-1)";
  EXPECT_EQ(derive("B(2)A(4,4)", rules, 1), "B(1)B(4)A(1,0)");
  EXPECT_EQ(derive("B(2)A(4,4)", rules, 2), "B(0)B(3)A(2,1)");
  EXPECT_EQ(derive("B(2)A(4,4)", rules, 3), "CB(2)A(4,3)");
  EXPECT_EQ(derive("B(2)A(4,4)", rules, 4), "CB(1)A(8,7)");
  EXPECT_EQ(derive("B(2)A(4,4)", rules, 5), "CB(0)B(8)A(1.14286,0)");
}

TEST(LSystemDerivation, AnEmptySuccessorErasesItsModule) {  // a fuzzer's find: nothing to copy is no copy
  EXPECT_EQ(derive("AB", "A =\nB = AB", 1), "AB");
  EXPECT_EQ(derive("AB", "A =\nB = AB", 3), "AB");
  EXPECT_EQ(derive("A[A]B", "A =", 1), "[]B");
}

TEST(LSystemDerivation, OneParametricRuleAppliesOnlyToItsParameterCount) {
  // A symbol with one rule and no condition is rewritten without choosing: the pattern's count decides.
  EXPECT_EQ(derive("A(1)A(1,2)A", "A(x) = B(x+1)A(x*2)", 1), "B(2)A(2)A(1,2)A");
  EXPECT_EQ(derive("A(1)A(1,2)A", "A(x) = B(x+1)A(x*2)", 2), "B(2)B(3)A(4)A(1,2)A");
  EXPECT_EQ(derive("A(1)A", "A(x) = F[+]A(x)", 2), "F[+]F[+]A(1)A");  // a successor of constants
}

// The peer workloads (bench/peers/cases.json), smaller: each spans several rewrite blocks.
TEST(LSystemDerivation, PeerWorkloadsAreExactAndIdenticalOnOneAndTwoThreads) {
  const std::string abop =
      "A(l,w) = !(w)F(l)[&(45)B(l*0.6,w*0.707)]/(137.5)A(l*0.9,w*0.707)\n"
      "B(l,w) = !(w)F(l)[-(45)$C(l*0.6,w*0.707)]C(l*0.9,w*0.707)\n"
      "C(l,w) = !(w)F(l)[+(45)$B(l*0.6,w*0.707)]B(l*0.9,w*0.707)";
  const std::string signal = "b" + std::string(100000, 'a');
  const std::vector<Params> cases = {lsys_params("F", "F=F[+F]F[-F]F", 7), lsys_params("A(1,10)", abop, 14),
                                     lsys_params(signal, "b < a = b\nb = a", 8)};
  std::vector<DerivedString> one, two;
  for (const std::size_t threads : {1, 2}) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    for (const auto& p : cases) (threads == 1 ? one : two).push_back(derive_lsystem(p, 1, nullptr, nullptr, 0));
  }
  for (std::size_t k = 0; k < cases.size(); ++k) EXPECT_EQ(one[k].text, two[k].text) << k;
  EXPECT_EQ(one[0].modules, 1u + 10u * (78125u - 1u) / 4u);  // 5^7 F, each adding 10 symbols
  EXPECT_EQ(one[1].modules, 7u * 16384u - 6u);               // 7 * 2^n - 6
  EXPECT_EQ(one[1].params, 81931u);
  EXPECT_EQ(one[1].text.substr(0, 41), "!(10)F(1)[&(45)!(7.07)F(0.6)[-(45)$!(4.99");
  EXPECT_EQ(one[2].text.substr(0, 10), "aaaaaaaaba");  // the signal moves one module per step
  EXPECT_EQ(counts(one[2])['b'], 1u);
}

TEST(LSystemDerivation, HoudiniReferenceExamples) {
  // "A(i):i<5 = A(i+1) A(i+1) will double each A a maximum of five times"
  const auto d = derive_lsystem(lsys_params("A(0)", "A(i):i<5 = A(i+1) A(i+1)", 8), 1, nullptr, nullptr, 0);
  EXPECT_EQ(d.modules, 32u);
  // edge rewriting with a 5th parameter, ':m=0 =' comparing with a lone '='
  const std::string rules =
      "F(i,j,k,l,m) :m=0 = F(i,j,k,l,0)+F(i,j,k,l,1)+\n"
      "F(i,j,k,l,m) :m=1 =-F(i,j,k,l,0)-F(i,j,k,l,1)";
  EXPECT_EQ(derive("F(1,1,3,3,0)", rules, 2), "F(1,1,3,3,0)+F(1,1,3,3,1)++-F(1,1,3,3,0)-F(1,1,3,3,1)+");
  // t is the iteration count during each rewrite; b = generations; the table of the reference
  const std::string lr = "l:t<b=l+r+\nr:t<b=-l-r\nl=F\nr=F";
  EXPECT_EQ(derive("l", lr, 1, {"b=1"}), "F");
  EXPECT_EQ(derive("l", lr, 2, {"b=2"}), "F+F+");
  EXPECT_EQ(derive("l", lr, 3, {"b=3"}), "F+F++-F-F+");
  // control length over time
  EXPECT_EQ(derive("A(1)", "A(i)= F(i)A(i*0.5)", 3), "F(1)F(0.5)F(0.25)A(0.125)");
  // user variables, i (module index), functions in degrees
  EXPECT_EQ(derive("AAA", "A = B(i*k)", 1, {"variables=k=2"}), "B(0)B(2)B(4)");
  EXPECT_EQ(derive("A", "A = B(sin(30), acos(0), max(2,3), min(2,3))", 1), "B(0.5,90,3,2)");
  EXPECT_EQ(derive("A(4)", "A(x): x > 3 & !(x > 5) | 0 = B", 1), "B");
  EXPECT_EQ(derive("A(2)", "A(x): x == 2 = B(x^3, 7 % 4)", 1), "B(8,3)");
  // a symbol with no applicable rule is copied; the first applicable rule wins
  EXPECT_EQ(derive("AB", "A = X\nA = Y", 1), "XB");
  // string parameters of a()
  EXPECT_EQ(derive("A", "A = a(\"Cd\", 1, 0, 1)F", 1), "a(\"Cd\",1,0,1)F");
}

TEST(LSystemDerivation, AgeCountsGenerationsSinceProduced) {
  EXPECT_EQ(derive("AB", "A = A\nB : g >= 2 = C", 3), "AC");
  EXPECT_EQ(derive("AB", "A = A\nB : g >= 2 = C", 2), "AB");
}

// ---------- probabilities ----------

std::map<char, std::size_t> stochastic_counts(const std::string& mode) {
  Params p = lsys_params(std::string(30000, 'A'), "A = X : 0.5\nA = Y : 0.5", 1, {"probability=" + mode});
  return counts(derive_lsystem(p, 7, nullptr, nullptr, 0));
}

double chi_square(const std::map<char, std::size_t>& got, const std::map<char, double>& expected_fraction, double n) {
  double chi = 0.0;
  for (const auto& [c, f] : expected_fraction) {
    const double e = f * n;
    const double o = got.count(c) ? static_cast<double>(got.at(c)) : 0.0;
    chi += (o - e) * (o - e) / e;
  }
  return chi;
}

TEST(LSystemProbability, SequentialRulesEachFireWithTheirOwnChance) {
  // X 50%, then Y 50% of the rest, the remaining 25% copied; chi-square, 2 dof, p = 0.001: 13.8
  const auto c = stochastic_counts("sequential");
  EXPECT_LT(chi_square(c, {{'X', 0.5}, {'Y', 0.25}, {'A', 0.25}}, 30000), 13.8);
  // and a wrong reading (normalized) would be far off
  EXPECT_GT(chi_square(c, {{'X', 0.5}, {'Y', 0.5 - 1e-9}, {'A', 1e-9}}, 30000), 1000.0);
}

TEST(LSystemProbability, NormalizedRulesShareOneChoice) {
  const auto c = stochastic_counts("normalized");
  EXPECT_EQ(c.count('A'), 0u);
  EXPECT_LT(chi_square(c, {{'X', 0.5}, {'Y', 0.5}}, 30000), 10.8);  // 1 dof, p = 0.001
  // weights under 1 leave the rest to the next rule without a probability
  Params p = lsys_params(std::string(30000, 'A'), "A = X : 0.2\nA = Y : 0.2\nA = Z", 1, {"probability=normalized"});
  const auto c2 = counts(derive_lsystem(p, 3, nullptr, nullptr, 0));
  EXPECT_LT(chi_square(c2, {{'X', 0.2}, {'Y', 0.2}, {'Z', 0.6}}, 30000), 13.8);
  // percentages: ': 80' is 0.8
  Params q = lsys_params(std::string(30000, 'A'), "A = X : 80", 1);
  const auto c3 = counts(derive_lsystem(q, 3, nullptr, nullptr, 0));
  EXPECT_LT(chi_square(c3, {{'X', 0.8}, {'A', 0.2}}, 30000), 10.8);
}

// probability_units: ':1.5' once read as 1.5% under the rule that a probability above 1 is a
// percentage, while ':1' was certain. Under auto it is refused as ambiguous, naming its line; fraction
// reads the reference's definition (0 to 1) and percent reads 0 to 100.
TEST(LSystemProbability, UnitsReadProbabilitiesAsAskedAndRefuseTheAmbiguous) {
  const std::string a = test::error_of(
      [] { derive_lsystem(lsys_params(std::string(100, 'A'), "A = X : 1.5", 1), 3, nullptr, nullptr, 0); });
  EXPECT_NE(a.find("parameter 'rules':1: probability 1.5 is ambiguous"), std::string::npos) << a;
  EXPECT_NE(a.find("set probability_units=fraction or percent"), std::string::npos) << a;
  // fraction: 0.5 is half; 1.5 is out of range
  const auto half = counts(derive_lsystem(
      lsys_params(std::string(30000, 'A'), "A = X : 0.5", 1, {"probability_units=fraction"}), 3, nullptr, nullptr, 0));
  EXPECT_LT(chi_square(half, {{'X', 0.5}, {'A', 0.5}}, 30000), 10.8);
  EXPECT_NE(test::error_of([] {
              derive_lsystem(lsys_params("A", "A = X : 1.5", 1, {"probability_units=fraction"}), 3, nullptr, nullptr,
                             0);
            }).find("probability 1.5: expected 0 to 1 with probability_units=fraction"),
            std::string::npos);
  // percent: ': 1' is 1%, not certain
  const auto one = counts(derive_lsystem(
      lsys_params(std::string(30000, 'A'), "A = X : 1", 1, {"probability_units=percent"}), 3, nullptr, nullptr, 0));
  EXPECT_LT(chi_square(one, {{'X', 0.01}, {'A', 0.99}}, 30000), 10.8);
  // auto: a percentage of 2 or more still reads as one
  const auto two = counts(derive_lsystem(lsys_params(std::string(30000, 'A'), "A = X : 2", 1), 3, nullptr, nullptr, 0));
  EXPECT_LT(chi_square(two, {{'X', 0.02}, {'A', 0.98}}, 30000), 10.8);
}

TEST(LSystemProbability, SeedChangesTheStringAndRepeats) {
  Params p = lsys_params("A", "A = A[+A] : 0.5\nA = AA", 8);
  const auto a = derive_lsystem(p, 1, nullptr, nullptr, 0).text;
  EXPECT_EQ(a, derive_lsystem(p, 1, nullptr, nullptr, 0).text);
  EXPECT_NE(a, derive_lsystem(p, 2, nullptr, nullptr, 0).text);
}

// ---------- errors ----------

TEST(LSystemErrors, NameSourceLineColumnAndWhatWasExpected) {
  auto err = [](const std::string& premise, const std::string& rules) {
    return test::error_of([&] { derive(premise, rules, 1); });
  };
  EXPECT_NE(err("A", "A = B\nA(i = B").find("parameter 'rules':2:"), std::string::npos) << err("A", "A = B\nA(i = B");
  EXPECT_NE(err("A", "A = B(q)").find("unknown variable 'q'"), std::string::npos);
  EXPECT_NE(err("A", "A = B(q)").find("parameter 'rules':1:7"), std::string::npos) << err("A", "A = B(q)");
  EXPECT_NE(err("A", "AB = C").find("expected one predecessor symbol"), std::string::npos);
  EXPECT_NE(err("A", "A B").find("expected '=' or '->'"), std::string::npos);
  EXPECT_NE(err("A", "A = B(1+)").find("expected a number"), std::string::npos);
  EXPECT_NE(err("A", "A = B(foo(1))").find("unknown function 'foo'"), std::string::npos);
  EXPECT_NE(err("A", "A = B(1,2,3,4,5,6)").find("at most 5"), std::string::npos);
  EXPECT_NE(err("A", "A = B : 2 + ").find("the probability"), std::string::npos);
  // A repeated name bound two arguments to one name, silently: the rule grew with one of them.
  EXPECT_NE(err("A(1,2)", "A(x,x) = F(x)").find("the parameter name 'x' appears twice"), std::string::npos);
  EXPECT_NE(err("A(1)B(2)", "A(x) > B(x) = F(x)").find("'x' appears twice"), std::string::npos);
  EXPECT_NE(err("", "A = B").find("premise is empty"), std::string::npos);

  const auto dir = test::temp_dir("lsys-errors");
  const std::string file = test::write_text(dir / "bad.lsys", "# a comment\npremise: A\ngeneratons: 3\nA = B\n");
  const std::string e1 = test::error_of([&] {
    Params p = default_params(find_algorithm("lsystem"));
    p.set("grammar", file);
    derive_lsystem(p, 1, nullptr, nullptr, 0);
  });
  EXPECT_NE(e1.find("bad.lsys:3:1: unknown setting 'generatons' (did you mean 'generations'?)"), std::string::npos)
      << e1;
  const std::string file2 = test::write_text(dir / "bad2.lsys", "premise: A\n\nA = B(\n");
  const std::string e2 = test::error_of([&] {
    Params p = default_params(find_algorithm("lsystem"));
    p.set("grammar", file2);
    derive_lsystem(p, 1, nullptr, nullptr, 0);
  });
  EXPECT_NE(e2.find("bad2.lsys:3:"), std::string::npos) << e2;
  const std::string file3 = test::write_text(dir / "bad3.lsys", "premise: A\ngenerations: many\n");
  const std::string e3 = test::error_of([&] {
    Params p = default_params(find_algorithm("lsystem"));
    p.set("grammar", file3);
    derive_lsystem(p, 1, nullptr, nullptr, 0);
  });
  EXPECT_NE(e3.find("bad3.lsys:2:"), std::string::npos) << e3;
}

TEST(LSystemErrors, RunawayGrowthStopsWithAClearError) {
  const std::string e = test::error_of([] { derive("F", "F = FF", 40, {"max_symbols=100000"}); });
  EXPECT_NE(e.find("runaway"), std::string::npos) << e;
  EXPECT_NE(e.find("max_symbols=100000"), std::string::npos) << e;
}

// ---------- the turtle ----------

class LSystemTurtle : public test::OnEnvelope {
 protected:
  static Plant grow(const std::string& premise, const std::string& rules, double generations,
                    std::vector<std::string> extra = {}, int threads = 0) {
    std::vector<std::string> sets = {
        "premise=" + premise, "rules=" + rules, "generations=" + std::to_string(generations),
        "start=origin",       "step_size=1",    "thickness=0.1"};
    sets.insert(sets.end(), extra.begin(), extra.end());
    return test::grow("lsystem", *scene_, *query_, sets, threads);
  }
};

TEST_F(LSystemTurtle, KochIslandClosesWithExactLengthsAndRightAngles) {
  const Plant p = grow("F-F-F-F", "F = F-F+F+FF-F-F+F", 2, {"angle=90"});
  ASSERT_EQ(p.nodes.size(), 4u * 64u + 1u);                                            // a root and one node per F
  EXPECT_LT(glm::distance(p.nodes.front().position, p.nodes.back().position), 1e-4f);  // closes
  for (std::size_t k = 1; k < p.nodes.size(); ++k) {
    const glm::vec3 d = p.nodes[k].position - p.nodes[static_cast<std::size_t>(p.nodes[k].parent)].position;
    EXPECT_NEAR(glm::length(d), 1.0f, 1e-5f);
    EXPECT_NEAR(std::fabs(d.x) + std::fabs(d.y), 1.0f, 1e-5f);  // axis-aligned in the XY plane
    EXPECT_NEAR(d.z, 0.0f, 1e-6f);
    EXPECT_EQ(p.nodes[k].parent, static_cast<std::int32_t>(k - 1));
  }
  EXPECT_NEAR(p.total_length(), 256.0, 1e-3);
}

TEST_F(LSystemTurtle, ConventionsTurnOppositeWays) {
  // F[+F]: ABOP's + turns left (toward -X when heading +Y, seen from +Z); Houdini's turns right
  const Plant abop = grow("F[+F]", "", 0, {"angle=90", "convention=abop"});
  const Plant houdini = grow("F[+F]", "", 0, {"angle=90", "convention=houdini"});
  ASSERT_EQ(abop.nodes.size(), 3u);
  EXPECT_NEAR(abop.nodes[2].position.x, -1.0f, 1e-6f);
  EXPECT_NEAR(abop.nodes[2].position.y, 1.0f, 1e-6f);
  EXPECT_NEAR(houdini.nodes[2].position.x, 1.0f, 1e-6f);
  // ABOP fig. 1.24a is a mirror image between the conventions
  const Plant a = grow("F", "F=F[+F]F[-F]F", 3, {"angle=25.7", "convention=abop"});
  const Plant h = grow("F", "F=F[+F]F[-F]F", 3, {"angle=25.7", "convention=houdini"});
  ASSERT_EQ(a.nodes.size(), h.nodes.size());
  for (std::size_t k = 0; k < a.nodes.size(); ++k) {
    EXPECT_NEAR(a.nodes[k].position.x, -h.nodes[k].position.x, 1e-5f);
    EXPECT_NEAR(a.nodes[k].position.y, h.nodes[k].position.y, 1e-5f);
  }
  // branch order and connectivity: one root, the branch has order 1
  EXPECT_EQ(abop.nodes[2].order, 1);
  EXPECT_EQ(abop.nodes[2].parent, 1);
}

TEST_F(LSystemTurtle, PitchRollAndTurnAround) {
  // & pitches the heading toward -U (= -Z at the start): F&F goes to (0, 1, -1)
  const Plant p = grow("F&F", "", 0, {"angle=90"});
  EXPECT_NEAR(p.nodes[2].position.z, -1.0f, 1e-6f);
  EXPECT_NEAR(p.nodes[2].position.y, 1.0f, 1e-6f);
  // a roll by 90 then a turn: the turn happens in the YZ plane
  const Plant r = grow("F\\+F", "", 0, {"angle=90", "convention=abop"});
  EXPECT_NEAR(r.nodes[2].position.x, 0.0f, 1e-6f);
  EXPECT_NEAR(std::fabs(r.nodes[2].position.z), 1.0f, 1e-6f);
  // | turns around: F|F comes back to the root
  const Plant back = grow("F|F", "", 0);
  EXPECT_LT(glm::length(back.nodes[2].position - back.nodes[0].position), 1e-6f);
  // f moves without drawing: a second root
  const Plant gap = grow("FfF", "", 0);
  ASSERT_EQ(gap.nodes.size(), 4u);
  EXPECT_EQ(gap.nodes[2].parent, kNoParent);
  EXPECT_NEAR(gap.nodes[3].position.y, 3.0f, 1e-6f);
  // G moves on without a vertex: FGF has 3 nodes, the last segment 2 long
  const Plant g = grow("FGF", "", 0);
  ASSERT_EQ(g.nodes.size(), 3u);
  EXPECT_NEAR(g.nodes[2].position.y, 3.0f, 1e-6f);
  // explicit parameters: F(2) goes 2, H half a step, +(90)
  const Plant q = grow("F(2)+(90)H", "", 0, {"convention=abop"});
  EXPECT_NEAR(q.nodes[1].position.y, 2.0f, 1e-6f);
  EXPECT_NEAR(q.nodes[2].position.x, -0.5f, 1e-6f);
}

// The grammar a Houdini user wrote for a cherry branch: J places flowers and K leaves. kind_j and kind_k
// say so, organ_j names J's geometry, and each comes out labelled and shaped as asked.
TEST_F(LSystemTurtle, PerSymbolKindsAndShapes) {
  const Plant p = grow("FJ(0.2)K(0.3)M", "", 0, {"kind_j=flower", "kind_k=leaf", "organ_j=blossom:petals=6"});
  ASSERT_EQ(p.organs.size(), 3u);
  EXPECT_EQ(p.organs[0].kind, OrganKind::Flower);
  EXPECT_EQ(p.organs[1].kind, OrganKind::Leaf);
  EXPECT_EQ(p.organs[2].kind, OrganKind::Bud);  // M keeps its default
  ASSERT_EQ(p.organ_shapes, std::vector<std::string>{"blossom:petals=6"});
  EXPECT_EQ(p.organs[0].shape, 0u);
  EXPECT_EQ(p.organs[1].shape, kKindShape);  // K: a leaf's own shape
  EXPECT_FLOAT_EQ(p.organs[0].size, 0.2f);
  const OrganShapes shapes(p);
  EXPECT_EQ(shapes.of(p.organs[0]).mesh.triangles.size(), 60u);  // six petals of ten triangles
  EXPECT_EQ(shapes.of(p.organs[1]).name, "leaf");
  EXPECT_EQ(shapes.of(p.organs[2]).name, "bud");
  // An unknown shape is refused before anything grows, naming the parameter and the choices.
  const std::string e = test::error_of([&] { (void)grow("FJ", "", 0, {"organ_j=tulip"}); });
  EXPECT_NE(e.find("parameter organ_j: unknown organ shape 'tulip'; expected one of leaf, blossom, half_bloom, bud"),
            std::string::npos)
      << e;
  const std::string f = test::error_of([&] { (void)grow("FJ", "", 0, {"organ_k=/no/such/petal.obj"}); });
  EXPECT_NE(f.find("/no/such/petal.obj"), std::string::npos) << f;
}

TEST_F(LSystemTurtle, DollarLevelsTheLeftVector) {
  // after arbitrary rotations, $ makes L horizontal (the organ's local +X is L)
  const Plant p = grow("F&(30)/(50)+(20)$J", "", 0);
  ASSERT_EQ(p.organs.size(), 1u);
  const glm::vec3 left = p.organs[0].orientation * glm::vec3(1, 0, 0);
  const glm::vec3 head = p.organs[0].orientation * glm::vec3(0, 0, 1);
  EXPECT_NEAR(left.y, 0.0f, 1e-5f);
  EXPECT_GT(glm::length(head), 0.99f);
  // $(x,y,z) points the turtle at the point
  const Plant q = grow("F$(3,1,0)F", "", 0);
  EXPECT_NEAR(q.nodes[2].position.x, 1.0f, 1e-5f);
  EXPECT_NEAR(q.nodes[2].position.y, 1.0f, 1e-5f);
}

TEST_F(LSystemTurtle, ScalesWidthsOrgansPolygonsGroupsAttributes) {
  const Plant p = grow("F\"F!F_F?F", "", 0, {"step_scale=0.5", "thickness_scale=0.5"});
  ASSERT_EQ(p.nodes.size(), 6u);
  EXPECT_NEAR(p.nodes[2].position.y - p.nodes[1].position.y, 0.5f, 1e-6f);
  EXPECT_NEAR(p.nodes[4].position.y - p.nodes[3].position.y, 1.0f, 1e-6f);  // _ undid "
  EXPECT_NEAR(p.nodes[1].radius, 0.05f, 1e-7f);                             // width 0.1 -> radius 0.05
  EXPECT_NEAR(p.nodes[3].radius, 0.025f, 1e-7f);
  EXPECT_NEAR(p.nodes[5].radius, 0.05f, 1e-7f);

  const Plant o = grow("FJ(0.5,0,1,2,3)K(0.25)M", "", 0);
  ASSERT_EQ(o.organs.size(), 3u);
  EXPECT_EQ(o.organs[0].kind, OrganKind::Leaf);
  EXPECT_EQ(o.organs[1].kind, OrganKind::Flower);
  EXPECT_EQ(o.organs[2].kind, OrganKind::Bud);
  EXPECT_FLOAT_EQ(o.organs[0].size, 0.5f);
  EXPECT_FLOAT_EQ(o.organs[2].size, 1.0f);  // default: the step
  EXPECT_EQ(o.organs[0].stamp, (std::array<float, 3>{1, 2, 3}));
  EXPECT_EQ(o.organs[0].node, 1);

  const Plant poly = grow("{.f+.f+.f+.}", "", 0, {"angle=90"});
  ASSERT_EQ(poly.polygons.size(), 1u);
  EXPECT_EQ(poly.polygons[0].vertices.size(), 4u);

  const Plant cut = grow("F[F%FF]F", "", 0);
  EXPECT_EQ(cut.nodes.size(), 4u);  // root, F, the branch's first F, the last F

  const Plant grp = grow("a(\"Cd\",1,0,1)Fg[gF]F", "", 0);
  ASSERT_EQ(grp.node_groups.size(), grp.nodes.size());
  EXPECT_EQ(grp.node_groups[1], -1);
  EXPECT_EQ(grp.node_groups[2], 1);  // the branch's g
  EXPECT_EQ(grp.node_groups[3], 0);  // back on the main axis: the first g
  ASSERT_EQ(grp.node_attributes.size(), 1u);
  EXPECT_EQ(grp.node_attributes[0].name, "Cd");
  EXPECT_EQ(grp.node_attributes[0].components, 3);
  EXPECT_FLOAT_EQ(grp.node_attributes[0].values[3 * 1 + 2], 1.0f);
  EXPECT_EQ(grp.validate(), "");
}

TEST_F(LSystemTurtle, TropismBendsTowardGravity) {
  const Plant p = grow("F+(90)FTF", "", 0, {"gravity=0.5", "convention=abop"});
  // heading -X then T rotates it toward -Y by 0.5 rad
  const glm::vec3 d = p.nodes[3].position - p.nodes[2].position;
  EXPECT_NEAR(d.y, -std::sin(0.5f), 1e-5f);
  EXPECT_NEAR(d.x, -std::cos(0.5f), 1e-5f);
}

TEST_F(LSystemTurtle, FractionalGenerationsGrowContinuously) {
  // A -> F A: at 2.5 generations the newest F is half a step
  const Plant p = grow("A", "A = FA", 2.5);
  ASSERT_EQ(p.nodes.size(), 4u);
  EXPECT_NEAR(p.nodes[3].position.y - p.nodes[2].position.y, 0.5f, 1e-6f);
  EXPECT_NEAR(p.nodes[2].position.y, 2.0f, 1e-6f);
  // new angles scale too: A -> +(90)F A at 0.5 turns 45 degrees
  const Plant q = grow("FA", "A = +(90)FA", 0.5, {"convention=abop"});
  const glm::vec3 d = q.nodes[2].position - q.nodes[1].position;
  EXPECT_NEAR(std::atan2(-d.x, d.y), glm::radians(45.0f), 1e-5f);
}

TEST_F(LSystemTurtle, InTestsTheEnvelopeAndArcLengthIsReadable) {
  // the topiary example stays inside the envelope (plus a step) and grows something there
  const Plant p = test::grow("lsystem", *scene_, *query_, {"grammar=topiary"});
  ASSERT_GT(p.nodes.size(), 100u);
  const Shape& env = *scene_->envelope;
  std::size_t inside = 0;
  for (const auto& n : p.nodes) inside += query_->inside_shape(env, n.position) ? 1 : 0;
  EXPECT_GT(inside, p.nodes.size() / 2);
  // arc length: a rule that stops at A >= 3 grows exactly 3 unit steps
  const Plant q = grow("A", "A: A < 3 = FA", 10);
  EXPECT_EQ(q.nodes.size(), 4u);
}

TEST_F(LSystemTurtle, DeterministicAcrossThreadCounts) {
  // a stochastic, parametric, context-sensitive grammar large enough to span many rewrite blocks
  const std::string rules =
      "A(l) = F(l)[+A(l*0.7)][-A(l*0.8)]/A(l*0.9) : 0.7\n"
      "A(l) = F(l)[&A(l*0.8)]A(l*0.9)\n"
      "F(l) > [ = F(l*1.01)";
  const std::vector<std::string> extra = {"angle=20", "max_symbols=5000000"};
  const Plant one = grow("A(1)", rules, 11, extra, 1);
  const Plant two = grow("A(1)", rules, 11, extra, 2);
  ASSERT_GT(one.nodes.size(), 20000u);  // more than 32768 modules: several rewrite blocks
  EXPECT_EQ(one.geometry_hash(), two.geometry_hash());
}

TEST_F(LSystemTurtle, SurfaceWrapKeepsNodesOnTheSurface) {
  const Scene column = load_scene("column");
  const SceneQuery q(column);
  const Plant p = test::grow("lsystem", column, q, {"surface=wrap", "grammar=bracketed-plant", "wrap_offset=0.01"});
  ASSERT_GT(p.nodes.size(), 100u);
  for (const auto& n : p.nodes) {
    const float d = q.closest_point(n.position).distance;
    ASSERT_NEAR(d, 0.01f, 2e-3f);
  }
}

TEST_F(LSystemTurtle, SurfaceAvoidEndsABranchBeforeASolid) {
  // Two straight branches from 0.62 m in front of the wall (its faces at z = +-0.1): '&' heads one at the
  // wall (-Z) and '^' the other away (+Z), 30 steps of 5 cm each.
  const Scene wall = load_scene("wall");
  const SceneQuery q(wall);
  const std::vector<std::string> params = {"start=origin", "start_position=0,1,0.62", "premise=[&(90)A][^(90)A]",
                                           "rules=A = F(0.05)A", "generations=30"};
  auto z_range = [](const Plant& p, bool toward) {
    float nearest = 1e9f, farthest = -1e9f;
    std::size_t n = 0;
    for (const auto& nd : p.nodes)
      if ((nd.position.z < 0.6f) == toward) {
        nearest = std::min(nearest, nd.position.z), farthest = std::max(farthest, nd.position.z), ++n;
      }
    return std::tuple{nearest, farthest, n};
  };
  auto free = params, avoid = params;
  free.push_back("surface=free");
  avoid.push_back("surface=avoid");
  const Plant through = test::grow("lsystem", wall, q, free);
  const Plant stopped = test::grow("lsystem", wall, q, avoid);
  EXPECT_LT(std::get<0>(z_range(through, true)), -0.5f) << "a free turtle passes through the wall";
  const auto [near_z, far_z, n] = z_range(stopped, true);
  EXPECT_GT(near_z, 0.1f) << "no node in or behind the wall";
  EXPECT_LE(near_z, 0.1f + 0.05f + 1e-4f) << "the branch goes on until the step that would enter it";
  EXPECT_EQ(n, 10u) << "ten steps of 5 cm from z = 0.62 end at z = 0.12; the eleventh would end in the wall";
  EXPECT_EQ(std::get<2>(z_range(stopped, false)), std::get<2>(z_range(through, false)))
      << "the branch heading away is untouched";
  for (const auto& nd : stopped.nodes) EXPECT_FALSE(q.inside(nd.position));
}

TEST(LSystemExamples, EveryExampleGrows) {
  const auto names = lsystem_examples();
  ASSERT_GE(names.size(), 6u);
  const Scene scene = load_scene("envelope");
  const SceneQuery query(scene);
  for (const auto& name : names) {
    const Plant p = test::grow("lsystem", scene, query, {"grammar=" + name});
    EXPECT_GT(p.nodes.size(), 10u) << name;
    EXPECT_EQ(p.validate(), "") << name;
  }
  // the bush carries leaves and flowers
  const Plant bush = test::grow("lsystem", scene, query, {"grammar=bush"});
  std::size_t leaves = 0, flowers = 0;
  for (const auto& o : bush.organs) {
    leaves += o.kind == OrganKind::Leaf;
    flowers += o.kind == OrganKind::Flower;
  }
  EXPECT_GT(leaves, 0u);
  EXPECT_GT(flowers, 0u);
}

TEST(LSystemExpr, CompilesOnceAndFoldsConstants) {
  lsys::Expr e;
  lsys::ExprError err;
  std::vector<std::string> formals = {"x"};
  ASSERT_TRUE(lsys::ExprCompiler::compile("2 * 3 + 1", {&formals, nullptr}, e, err));
  EXPECT_TRUE(e.constant());
  EXPECT_EQ(e.constant_value(), 7.0);
  ASSERT_TRUE(lsys::ExprCompiler::compile("x * 2 - -1", {&formals, nullptr}, e, err));
  EXPECT_FALSE(e.constant());
  struct H final : lsys::ExprHost {
    double in(double, double, double) const override { return 0; }
    double pic(double, double, double) const override { return 0; }
    double rand(double) const override { return 0; }
    double chan(double) const override { return 0; }
  } host;
  double env[lsys::kMaxSlots] = {};
  env[0] = 5.0;
  EXPECT_EQ(e.eval(env, host), 11.0);
  ASSERT_TRUE(lsys::ExprCompiler::compile("2 ^ 3 ^ 2", {&formals, nullptr}, e, err));
  EXPECT_EQ(e.constant_value(), 512.0);  // right-associative
  ASSERT_TRUE(lsys::ExprCompiler::compile("-2 ^ 2", {&formals, nullptr}, e, err));
  EXPECT_EQ(e.constant_value(), -4.0);
  EXPECT_FALSE(lsys::ExprCompiler::compile("x +", {&formals, nullptr}, e, err));
  EXPECT_EQ(err.offset, 3u);
}

TEST(LSystemExpr, ShortShapesGiveTheStackMachinesBitsAndErrors) {
  // x*0.6 runs without the stack machine, x*0.6*1 with it: the same product to the bit.
  std::vector<std::string> formals = {"x"};
  struct H final : lsys::ExprHost {
    double in(double, double, double) const override { return 0; }
    double pic(double, double, double) const override { return 0; }
    double rand(double) const override { return 0; }
    double chan(double) const override { return 0; }
  } host;
  const auto compiled = [&](const std::string& text) {
    lsys::Expr e;
    lsys::ExprError err;
    EXPECT_TRUE(lsys::ExprCompiler::compile(text, {&formals, nullptr}, e, err)) << text;
    return e;
  };
  double env[lsys::kMaxSlots] = {};
  for (const double x : {0.1, -3.7, 1e-300, 123456.789}) {
    env[0] = x;
    for (const char* op : {"*", "/", "+", "-"}) {
      const std::string o(op);
      EXPECT_EQ(compiled("x" + o + "0.6").eval(env, host), compiled("x" + o + "0.6*1").eval(env, host)) << op << x;
      EXPECT_EQ(compiled("0.6" + o + "x").eval(env, host), compiled("(0.6" + o + "x)*1").eval(env, host)) << op << x;
    }
    EXPECT_EQ(compiled("x").eval(env, host), x);
  }
  env[0] = 2.0;
  EXPECT_EQ(compiled("x - 0.5").eval(env, host), 1.5);
  EXPECT_EQ(compiled("3 / x").eval(env, host), 1.5);
  try {
    (void)compiled("1 / (x - 2)").eval(env, host);  // the general path, for comparison
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a division by zero"), std::string::npos) << e.what();
  }
  env[0] = 0.0;
  try {
    (void)compiled("1 / x").eval(env, host);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "'1 / x' gave inf, from a division by zero");
  }
  env[0] = 1e300;
  lsys::Expr big = compiled("x * 10");
  big.set_origin("the argument", true);
  try {
    (void)big.eval(env, host);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("beyond the largest module parameter"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace growbench
