// Grammars of the Houdini L-system dialect: premise, rules, and `.lsys` grammar files.
//
// Rule syntax: [left_context <] symbol [> right_context] [: condition] = replacement [: probability]
// ("->" may replace "="). A symbol is one printable ASCII character other than ( ) , : = < > and
// space; it may carry up to five parameters, e.g. A(i+1, j*0.5). Separators are found at parenthesis
// depth 0: the rule's "=" is the first "->", else the last lone "=" (so Houdini's ":m=0 = ..."
// compares m with 0); the condition follows the first ":" of the left side; the probability follows
// the last ":" of the right side (a value over 1 is a percentage: ": 80" means 0.8).
//
// A pattern module without parentheses matches its symbol with any parameters; A(i,j) matches an A
// with exactly two. Every error names SOURCE:LINE:COLUMN and what was expected.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/lsystem/expr.hpp"

namespace growbench::lsys {

constexpr int kMaxParams = 5;

struct Pattern {
  char symbol = 0;
  std::vector<std::string> formals;
  bool has_parens = false;
};

struct OutModule {
  char symbol = 0;
  std::vector<Expr> args;
};

struct Rule {
  std::vector<Pattern> left;  // left context, in string order
  Pattern pred;
  std::vector<Pattern> right;  // right context, may contain '[' and ']'
  Expr condition;              // empty: always true
  std::vector<OutModule> successor;
  Expr probability;   // empty: no probability
  std::string where;  // "SOURCE:LINE" for messages
  std::string text;
  // Formal slots: the predecessor's formals first, then the left context's, then the right's.
  std::vector<std::string> formals;
  bool uses_turtle = false;  // a condition, probability or argument reads the turtle's state
  bool uses_age = false;
  bool has_context = false;
  // Filled when every argument of the successor is a constant: the encoded output.
  bool static_successor = false;
  std::vector<std::uint16_t> static_symbols;
  std::vector<float> static_params;
  std::uint32_t out_params = 0;  // parameters written by one application
};

// A source of grammar text: a file name (or "parameter 'rules'") for messages, and the text.
struct GrammarText {
  std::string source;
  std::string text;
  std::size_t first_line = 1;    // line number of the text's first line in `source`
  std::size_t first_column = 1;  // column of the text's first character on that line
};

struct Grammar {
  std::vector<OutModule> premise;
  std::vector<Rule> rules;
  std::vector<std::string> user_variables;                // single letters, slot kUserVar0 + k
  std::vector<std::string> strings;                       // interned string literals: a("Cd", ...)
  std::bitset<128> ignore;                                // context ignore list
  std::array<std::vector<std::uint16_t>, 128> rules_for;  // rule indices per predecessor symbol
  bool uses_turtle = false;
  bool uses_age = false;
  bool has_context = false;
  // What parses but is likely not what was meant, FILE:LINE:COLUMN first: a command that takes a number
  // followed by digits ('/30', read as '/' and the symbols '3' and '0') where no rule rewrites those digits.
  std::vector<std::string> warnings;
};

// Symbols that may appear in strings (printable ASCII except the separators).
bool is_symbol_char(char c);

// Parses rules (one per non-blank line; a line whose first non-space character is '#' is a comment)
// and the premise against the given user variables. Throws InputError naming SOURCE:LINE:COLUMN.
Grammar parse_grammar(const GrammarText& premise, const std::vector<GrammarText>& rules,
                      const std::vector<std::string>& user_variables, const std::string& ignore);

// A `.lsys` grammar file: "name: value" settings (name is a multi-letter parameter name, e.g.
// "generations: 3", "angle: 22.5", "variables: b=2, k=0.5") and rules on the other lines.
struct GrammarFile {
  struct Setting {
    std::string key, value;
    std::size_t line;
    std::size_t column;  // of the value's first character
  };
  std::string path;
  std::vector<Setting> settings;
  GrammarText rules;  // the rule lines (others blanked so line numbers stay true)
  // A setting's value as grammar text that knows its place in the file (for the premise: errors then
  // name PATH:LINE:COLUMN).
  [[nodiscard]] GrammarText setting_text(const Setting& setting) const;
};
// A UTF-8 byte order mark at the top of the file is skipped.
GrammarFile read_grammar_file(const std::string& path, const std::vector<std::string>& known_settings);
// A rules file as Houdini's "Read Rules From File" reads it: one rule per line, '#' comments.
GrammarText read_rules_file(const std::string& path);

// Parses "k=0.5, q=2" into (name, value) pairs; names are single letters not reserved by the dialect
// except b, c, d. Throws InputError naming `source`.
std::vector<std::pair<std::string, double>> parse_variables(const std::string& source, const std::string& text);

}  // namespace growbench::lsys
