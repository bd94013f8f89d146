#include "algorithms/lsystem/grammar.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "algorithms/lsystem/lstring.hpp"
#include "core/errors.hpp"
#include "core/params.hpp"
#include "core/utf8.hpp"

namespace growbench::lsys {

bool is_symbol_char(char c) {
  return c > 32 && c < 127 && c != '(' && c != ')' && c != ',' && c != ':' && c != '=' && c != '<' && c != '>';
}

namespace {

// The most of a rule or an expression a message quotes.
constexpr std::size_t kQuoted = 80;

// What a character that is not a symbol is told.
constexpr const char* kSymbolsAre = "symbols are printable ASCII characters other than ( ) , : = < >";

// A view of part of one line that knows its columns, for messages.
struct Span {
  std::string_view text;
  std::size_t column;  // 1-based column of text[0] in the line
};

class LineParser {
 public:
  // `where`: "SOURCE:LINE"; `context`: what the line is, for the errors of its expressions at derivation
  // ("rule 'A(x) = B(x/2)'", "the premise").
  LineParser(std::string where, std::string context, Grammar& g)
      : where_(std::move(where)), context_(std::move(context)), g_(g) {}

  [[noreturn]] void fail(std::size_t column, const std::string& what) const {
    throw InputError(fmt::format("{}:{}: {}", where_, column, what));
  }

  static Span trim(Span s) {
    std::size_t a = 0, b = s.text.size();
    while (a < b && std::isspace(static_cast<unsigned char>(s.text[a]))) ++a;
    while (b > a && std::isspace(static_cast<unsigned char>(s.text[b - 1]))) --b;
    return {s.text.substr(a, b - a), s.column + a};
  }

  // Top-level (parenthesis depth 0, outside string literals) positions where `pred` holds.
  template <class Pred>
  std::vector<std::size_t> top_level(Span s, Pred pred) const {
    std::vector<std::size_t> out;
    int depth = 0;
    bool quoted = false;
    for (std::size_t k = 0; k < s.text.size(); ++k) {
      const char c = s.text[k];
      if (depth > 0 && c == '"') quoted = !quoted;
      if (quoted) continue;
      if (c == '(')
        ++depth;
      else if (c == ')') {
        if (--depth < 0) fail(s.column + k, "unbalanced ')'");
      } else if (depth == 0 && pred(s.text, k)) {
        out.push_back(k);
      }
    }
    if (depth > 0) fail(s.column + s.text.size(), "expected ')' before the end of the rule");
    return out;
  }

  // Patterns: symbols with optional formal parameter names.
  std::vector<Pattern> patterns(Span s, bool allow_brackets) const {
    std::vector<Pattern> out;
    std::size_t k = 0;
    while (k < s.text.size()) {
      const char c = s.text[k];
      if (std::isspace(static_cast<unsigned char>(c))) {
        ++k;
        continue;
      }
      if (!is_symbol_char(c))
        fail(s.column + k, fmt::format("expected a symbol, found '{}' ({})", utf8_char_at(s.text, k), kSymbolsAre));
      if ((c == '[' || c == ']') && !allow_brackets)
        fail(s.column + k, "a predecessor or left context cannot contain '[' or ']'");
      Pattern p;
      p.symbol = c;
      ++k;
      std::size_t j = k;
      while (j < s.text.size() && s.text[j] == ' ') ++j;
      if (j < s.text.size() && s.text[j] == '(') {
        p.has_parens = true;
        const std::size_t close = s.text.find(')', j);
        if (close == std::string_view::npos) fail(s.column + j, "expected ')'");
        std::string_view inside = s.text.substr(j + 1, close - j - 1);
        std::size_t start = 0, col0 = s.column + j + 1;
        while (true) {
          const std::size_t comma = inside.find(',', start);
          const Span name =
              trim({inside.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start),
                    col0 + start});
          if (name.text.empty()) fail(name.column, "expected a parameter name");
          if (!(std::isalpha(static_cast<unsigned char>(name.text[0])) || name.text[0] == '_'))
            fail(name.column, fmt::format("expected a parameter name, found '{}'", name.text));
          for (char ch : name.text)
            if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'))
              fail(name.column, fmt::format("expected a parameter name, found '{}'", name.text));
          p.formals.emplace_back(name.text);
          if (comma == std::string_view::npos) break;
          start = comma + 1;
        }
        if (p.formals.size() > static_cast<std::size_t>(kMaxParams))
          fail(s.column + j, fmt::format("a symbol has at most {} parameters, found {}", kMaxParams, p.formals.size()));
        k = close + 1;
      }
      out.push_back(std::move(p));
    }
    return out;
  }

  // `module_parameter`: the value becomes a module's parameter (see Expr::set_origin).
  Expr expression(Span s, const ExprScope& scope, const char* what, bool module_parameter = false) const {
    const Span t = trim(s);
    if (t.text.empty()) fail(s.column, fmt::format("expected {}", what));
    Expr e;
    ExprError err;
    if (!ExprCompiler::compile(t.text, scope, e, err))
      fail(t.column + err.offset, fmt::format("in {}: {}", what, err.message));
    if (module_parameter && e.constant() && std::abs(e.constant_value()) > kMaxModuleParameter)
      fail(t.column, fmt::format("{} {:g} is out of range; a module's parameter is a 32-bit float, at most {:g}", what,
                                 e.constant_value(), kMaxModuleParameter));
    e.set_origin(fmt::format("{}:{}: in {}: {} '{}'", where_, t.column, context_, what, utf8_excerpt(t.text, kQuoted)),
                 module_parameter);
    return e;
  }

  // Modules with argument expressions (a successor or the premise).
  std::vector<OutModule> modules(Span s, const ExprScope& scope) {
    std::vector<OutModule> out;
    std::size_t k = 0;
    while (k < s.text.size()) {
      const char c = s.text[k];
      if (std::isspace(static_cast<unsigned char>(c))) {
        ++k;
        continue;
      }
      if (!is_symbol_char(c))
        fail(s.column + k, fmt::format("expected a symbol, found '{}' ({})", utf8_char_at(s.text, k), kSymbolsAre));
      OutModule m;
      m.symbol = c;
      ++k;
      note_bare_number(s, k);
      std::size_t j = k;
      while (j < s.text.size() && s.text[j] == ' ') ++j;
      if (j < s.text.size() && s.text[j] == '(') {
        // find the matching ')'
        int depth = 0;
        bool quoted = false;
        std::size_t close = j;
        std::vector<std::size_t> commas;
        for (; close < s.text.size(); ++close) {
          const char ch = s.text[close];
          if (ch == '"') quoted = !quoted;
          if (quoted) continue;
          if (ch == '(')
            ++depth;
          else if (ch == ')' && --depth == 0)
            break;
          else if (ch == ',' && depth == 1)
            commas.push_back(close);
        }
        if (close >= s.text.size()) fail(s.column + j, "expected ')' to close the parameter list");
        std::size_t start = j + 1;
        commas.push_back(close);
        for (std::size_t a = 0; a < commas.size(); ++a) {
          const Span arg = trim({s.text.substr(start, commas[a] - start), s.column + start});
          if (!arg.text.empty() && arg.text.front() == '"') {
            if (m.symbol != 'a' || a != 0)
              fail(arg.column, "a string is only allowed as the first parameter of a(attribute, v1, v2, v3)");
            if (arg.text.size() < 2 || arg.text.back() != '"') fail(arg.column, "expected a closing '\"'");
            const std::string name(arg.text.substr(1, arg.text.size() - 2));
            if (name.empty()) fail(arg.column, "expected an attribute name between the quotes");
            auto it = std::find(g_.strings.begin(), g_.strings.end(), name);
            if (it == g_.strings.end()) it = g_.strings.insert(g_.strings.end(), name);
            Expr e;
            ExprError err;
            ExprCompiler::compile(std::to_string(it - g_.strings.begin()), scope, e, err);
            m.args.push_back(std::move(e));
          } else {
            m.args.push_back(expression(arg, scope, "the parameter expression", true));
          }
          start = commas[a] + 1;
        }
        if (m.args.size() > static_cast<std::size_t>(kMaxParams))
          fail(s.column + j, fmt::format("a symbol has at most {} parameters, found {}", kMaxParams, m.args.size()));
        k = close + 1;
      }
      out.push_back(std::move(m));
    }
    return out;
  }

  // Digits straight after a turtle command that takes a number ('/30'): as written they are symbols of
  // their own, which parse_grammar keeps as a warning unless a rule rewrites one of them.
  void note_bare_number(Span s, std::size_t k) {
    constexpr std::string_view kTakesNumber = "+-&^\\/~!?;@\"_'#T";
    const char c = s.text[k - 1];
    if (kTakesNumber.find(c) == std::string_view::npos || k >= s.text.size()) return;
    std::size_t e = k;
    while (e < s.text.size() && (std::isdigit(static_cast<unsigned char>(s.text[e])) || s.text[e] == '.')) ++e;
    while (e > k && s.text[e - 1] == '.') --e;  // a trailing '.' is the polygon command
    if (e == k || s.text[k] == '.') return;
    const std::string_view digits = s.text.substr(k, e - k);
    pending.push_back(
        {fmt::format("{}:{}: '{}{}' reads as '{}' followed by the symbols '{}'; if {} is its argument, "
                     "write '{}({})'",
                     where_, s.column + k - 1, c, digits, c, fmt::join(digits, "', '"), digits, c, digits),
         std::string(digits)});
  }

  struct Pending {
    std::string message, symbols;
  };
  std::vector<Pending> pending;  // note_bare_number's, for parse_grammar to keep or drop

  Rule rule(Span line) {
    Rule r;
    r.text = std::string(trim(line).text);
    context_ = fmt::format("rule '{}'", utf8_excerpt(r.text, kQuoted));
    // the separator: the first top-level "->", else the last lone top-level "="
    std::size_t sep = std::string_view::npos, sep_len = 1;
    const auto arrows = top_level(
        line, [](std::string_view t, std::size_t k) { return t[k] == '-' && k + 1 < t.size() && t[k + 1] == '>'; });
    if (!arrows.empty()) {
      sep = arrows.front();
      sep_len = 2;
    } else {
      const auto eqs = top_level(line, [](std::string_view t, std::size_t k) {
        if (t[k] != '=') return false;
        if (k + 1 < t.size() && t[k + 1] == '=') return false;
        if (k > 0 && (t[k - 1] == '=' || t[k - 1] == '<' || t[k - 1] == '>' || t[k - 1] == '!')) return false;
        return true;
      });
      if (eqs.empty())
        fail(line.column + trim(line).text.size(), "expected '=' or '->' between the predecessor and the replacement");
      sep = eqs.back();
    }
    const Span lhs{line.text.substr(0, sep), line.column};
    const Span rhs{line.text.substr(sep + sep_len), line.column + sep + sep_len};

    // left side: [left <] pred [> right] [: condition]
    Span pred_part = lhs;
    Span cond{{}, 0};
    const auto colons = top_level(lhs, [](std::string_view t, std::size_t k) { return t[k] == ':'; });
    if (!colons.empty()) {
      pred_part = {lhs.text.substr(0, colons.front()), lhs.column};
      cond = {lhs.text.substr(colons.front() + 1), lhs.column + colons.front() + 1};
    }
    const auto lts = top_level(pred_part, [](std::string_view t, std::size_t k) { return t[k] == '<'; });
    const auto gts = top_level(pred_part, [](std::string_view t, std::size_t k) { return t[k] == '>'; });
    if (lts.size() > 1) fail(pred_part.column + lts[1], "expected one '<' (left context) at most");
    if (gts.size() > 1) fail(pred_part.column + gts[1], "expected one '>' (right context) at most");
    std::size_t p0 = 0, p1 = pred_part.text.size();
    if (!lts.empty()) {
      r.left = patterns({pred_part.text.substr(0, lts[0]), pred_part.column}, false);
      if (r.left.empty()) fail(pred_part.column + lts[0], "expected a left context before '<'");
      p0 = lts[0] + 1;
    }
    if (!gts.empty()) {
      if (gts[0] < p0) fail(pred_part.column + gts[0], "expected the right context '>' after the predecessor");
      r.right = patterns({pred_part.text.substr(gts[0] + 1), pred_part.column + gts[0] + 1}, true);
      if (r.right.empty()) fail(pred_part.column + gts[0], "expected a right context after '>'");
      p1 = gts[0];
    }
    const Span pred_span{pred_part.text.substr(p0, p1 - p0), pred_part.column + p0};
    auto preds = patterns(pred_span, false);
    if (preds.size() != 1)
      fail(trim(pred_span).column, preds.empty() ? "expected the predecessor symbol"
                                                 : fmt::format("expected one predecessor symbol, found {} ('{}')",
                                                               preds.size(), trim(pred_span).text));
    r.pred = std::move(preds[0]);
    r.has_context = !r.left.empty() || !r.right.empty();

    // One name, one value: with A(x,x) the rule would read one of two arguments and drop the other.
    auto add_formals = [&](const Pattern& p) {
      for (const auto& f : p.formals) {
        if (std::find(r.formals.begin(), r.formals.end(), f) != r.formals.end())
          fail(line.column, fmt::format("the parameter name '{}' appears twice in the rule's predecessor and "
                                        "contexts; expected a different name for each parameter",
                                        f));
        r.formals.push_back(f);
      }
    };
    add_formals(r.pred);
    for (const auto& p : r.left) add_formals(p);
    for (const auto& p : r.right) add_formals(p);
    if (r.formals.size() > static_cast<std::size_t>(kMaxFormals))
      fail(line.column,
           fmt::format("a rule may name at most {} parameters in its predecessor and contexts", int(kMaxFormals)));
    const ExprScope scope{&r.formals, &g_.user_variables};
    if (!cond.text.empty() || !colons.empty()) r.condition = expression(cond, scope, "the condition");

    // right side: replacement [: probability]
    Span repl = rhs;
    const auto rcolons = top_level(rhs, [](std::string_view t, std::size_t k) { return t[k] == ':'; });
    if (!rcolons.empty()) {
      repl = {rhs.text.substr(0, rcolons.back()), rhs.column};
      r.probability =
          expression({rhs.text.substr(rcolons.back() + 1), rhs.column + rcolons.back() + 1}, scope, "the probability");
      if (r.probability.constant() &&
          !(r.probability.constant_value() >= 0.0 && r.probability.constant_value() <= 100.0))
        fail(rhs.column + rcolons.back() + 1,
             fmt::format("expected a probability in [0, 1] (or a percentage up to 100), found {}",
                         r.probability.constant_value()));
    }
    r.successor = modules(repl, scope);

    auto note = [&](const Expr& e) {
      if (e.empty()) return;
      r.uses_turtle |= e.use().turtle;
      r.uses_age |= e.use().age;
    };
    note(r.condition);
    note(r.probability);
    r.static_successor = true;
    for (const auto& m : r.successor) {
      r.out_params += static_cast<std::uint32_t>(m.args.size());
      for (const auto& a : m.args) {
        note(a);
        if (!a.constant()) r.static_successor = false;
      }
    }
    if (r.static_successor) {
      for (const auto& m : r.successor) {
        r.static_symbols.push_back(encode(m.symbol, static_cast<int>(m.args.size())));
        for (const auto& a : m.args) r.static_params.push_back(static_cast<float>(a.constant_value()));
      }
    }
    return r;
  }

 private:
  std::string where_;
  std::string context_;
  Grammar& g_;
};

std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view l = text.substr(start, end - start);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    lines.push_back(l);
    if (end == text.size()) break;
    start = end + 1;
  }
  return lines;
}

bool blank_or_comment(std::string_view l) {
  std::size_t k = 0;
  while (k < l.size() && std::isspace(static_cast<unsigned char>(l[k]))) ++k;
  return k == l.size() || l[k] == '#';
}

// The file's text without the UTF-8 byte order mark some editors put first (columns count from after it).
std::string read_text(const std::string& path, const char* what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(fmt::format("cannot read {} '{}': it is a directory", what, path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read {} '{}'", what, path));
  std::ostringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  if (text.starts_with(kUtf8Bom)) text.erase(0, kUtf8Bom.size());
  return text;
}

}  // namespace

Grammar parse_grammar(const GrammarText& premise, const std::vector<GrammarText>& rules,
                      const std::vector<std::string>& user_variables, const std::string& ignore) {
  Grammar g;
  std::vector<LineParser::Pending> pending;
  g.user_variables = user_variables;
  for (std::size_t k = 0; k < ignore.size(); ++k) {
    const char c = ignore[k];
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    if (!is_symbol_char(c))
      throw InputError(fmt::format("context_ignore: '{}' is not a symbol ({})", utf8_char_at(ignore, k), kSymbolsAre));
    g.ignore.set(static_cast<unsigned char>(c));
  }
  for (const auto& src : rules) {
    const auto lines = split_lines(src.text);
    for (std::size_t k = 0; k < lines.size(); ++k) {
      if (blank_or_comment(lines[k])) continue;
      LineParser p(fmt::format("{}:{}", src.source, src.first_line + k), "a rule", g);
      Rule r = p.rule({lines[k], k == 0 ? src.first_column : 1});
      pending.insert(pending.end(), p.pending.begin(), p.pending.end());
      r.where = fmt::format("{}:{}", src.source, src.first_line + k);
      if (g.rules.size() >= 65535) throw InputError(fmt::format("{}: too many rules", r.where));
      g.rules_for[static_cast<unsigned char>(r.pred.symbol)].push_back(static_cast<std::uint16_t>(g.rules.size()));
      g.uses_turtle |= r.uses_turtle;
      g.uses_age |= r.uses_age;
      g.has_context |= r.has_context;
      g.rules.push_back(std::move(r));
    }
  }
  // the premise: one line of modules (several lines are joined)
  {
    const auto lines = split_lines(premise.text);
    for (std::size_t k = 0; k < lines.size(); ++k) {
      LineParser p(fmt::format("{}:{}", premise.source, premise.first_line + k), "the premise", g);
      const ExprScope scope{nullptr, &g.user_variables};
      auto mods = p.modules({lines[k], k == 0 ? premise.first_column : 1}, scope);
      pending.insert(pending.end(), p.pending.begin(), p.pending.end());
      for (auto& m : mods) {
        for (const auto& a : m.args) {
          g.uses_turtle |= a.use().turtle;
          g.uses_age |= a.use().age;
        }
        g.premise.push_back(std::move(m));
      }
    }
    if (g.premise.empty())
      throw InputError(fmt::format("{}: the premise is empty; expected at least one symbol", premise.source));
  }
  for (const auto& w : pending)
    if (std::none_of(w.symbols.begin(), w.symbols.end(),
                     [&](char d) { return !g.rules_for[static_cast<unsigned char>(d)].empty(); }))
      g.warnings.push_back(w.message);
  return g;
}

GrammarFile read_grammar_file(const std::string& path, const std::vector<std::string>& known_settings) {
  GrammarFile f;
  f.path = path;
  const std::string text = read_text(path, "grammar file");
  const auto lines = split_lines(text);
  std::string rules;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const std::string_view l = lines[k];
    bool is_setting = false;
    if (!blank_or_comment(l)) {
      std::size_t a = 0;
      while (a < l.size() && std::isspace(static_cast<unsigned char>(l[a]))) ++a;
      std::size_t b = a;
      while (b < l.size() && (std::isalnum(static_cast<unsigned char>(l[b])) || l[b] == '_')) ++b;
      std::size_t c = b;
      while (c < l.size() && (l[c] == ' ' || l[c] == '\t')) ++c;
      // A word of two or more letters followed by ':' or '=' is a setting (a rule's predecessor is one symbol).
      if (b - a >= 2 && c < l.size() && (l[c] == ':' || l[c] == '=') &&
          std::isalpha(static_cast<unsigned char>(l[a]))) {
        is_setting = true;
        const std::string key(l.substr(a, b - a));
        if (std::find(known_settings.begin(), known_settings.end(), key) == known_settings.end()) {
          const std::string near = closest_match(key, known_settings);
          // `AB = F` reads as a setting; if it was meant as a rule, say what a rule's predecessor is.
          const std::string as_rule =
              l[c] == '=' ? "; if this is a rule, its predecessor is one symbol (write 'A < B = ...' for a context)"
                          : "";
          throw InputError(fmt::format("{}:{}:{}: unknown setting '{}'{}{}; expected one of {}", path, k + 1, a + 1,
                                       key, near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near), as_rule,
                                       fmt::join(known_settings, ", ")));
        }
        for (const GrammarFile::Setting& earlier : f.settings)
          if (earlier.key == key)
            throw InputError(fmt::format("{}:{}:{}: '{}' is set twice (first at line {}); expected each setting once",
                                         path, k + 1, a + 1, key, earlier.line));
        const Span value = LineParser::trim({l.substr(c + 1), c + 2});
        f.settings.push_back({key, std::string(value.text), k + 1, value.column});
      }
    }
    if (!is_setting && !blank_or_comment(l)) rules.append(l);
    rules.push_back('\n');
  }
  f.rules = {path, rules, 1};
  return f;
}

GrammarText read_rules_file(const std::string& path) {
  return {path, read_text(path, "rules file"), 1};
}

GrammarText GrammarFile::setting_text(const Setting& setting) const {
  return {path, setting.value, setting.line, setting.column};
}

std::vector<std::pair<std::string, double>> parse_variables(const std::string& source, const std::string& text) {
  std::vector<std::pair<std::string, double>> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find_first_of(",;\n", start);
    if (end == std::string::npos) end = text.size();
    const std::string_view item = LineParser::trim({std::string_view(text).substr(start, end - start), 1}).text;
    if (!item.empty()) {
      const std::size_t eq = item.find('=');
      if (eq == std::string_view::npos)
        throw InputError(fmt::format("{}: expected NAME=VALUE, found '{}'", source, item));
      const std::string name(LineParser::trim({item.substr(0, eq), 1}).text);
      const std::string_view value = LineParser::trim({item.substr(eq + 1), 1}).text;
      const bool letter = name.size() == 1 && std::isalpha(static_cast<unsigned char>(name[0]));
      if (!letter) throw InputError(fmt::format("{}: variable names are single letters, found '{}'", source, name));
      if (reserved_slot(name) >= 0 && name != "b" && name != "c" && name != "d")
        throw InputError(fmt::format(
            "{}: '{}' is a reserved variable (a g i t x y z A L T U V W); choose another letter", source, name));
      double v = 0.0;
      const auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (ec == std::errc::result_out_of_range)
        throw InputError(fmt::format("{}: variable '{}': the number '{}' is out of range", source, name, value));
      if (ec != std::errc() || p != value.data() + value.size() || value.empty() || !std::isfinite(v))
        throw InputError(fmt::format("{}: variable '{}': expected a finite number, found '{}'", source, name, value));
      for (const auto& [n, _] : out)
        if (n == name) throw InputError(fmt::format("{}: variable '{}' is given twice", source, name));
      out.emplace_back(name, v);
    }
    if (end == text.size()) break;
    start = end + 1;
  }
  return out;
}

}  // namespace growbench::lsys
