#include "algorithms/lsystem/derive.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>

#include <sys/mman.h>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "core/errors.hpp"
#include "core/random.hpp"

namespace growbench::lsys {
namespace {

constexpr std::size_t kBlock = 1u << 15;  // modules per block
constexpr std::uint16_t kCopy = 0xffff;

double draw(std::uint64_t seed, std::uint64_t stream, int generation, std::size_t module, std::size_t rule) {
  const std::uint64_t bits = random_bits(seed ^ (static_cast<std::uint64_t>(generation) << 40), stream,
                                         (static_cast<std::uint64_t>(module) << 16) ^ rule);
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

std::size_t block_count(std::size_t n) {
  return (n + kBlock - 1) / kBlock;
}

}  // namespace

namespace detail {

void* allocate_buffer(std::size_t bytes) {
  constexpr std::size_t kHugePage = std::size_t{2} << 20;
  if (bytes < kHugePage) {
    if (void* p = std::malloc(std::max<std::size_t>(bytes, 1))) return p;
    throw std::bad_alloc();
  }
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (!p) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  (void)madvise(p, rounded, MADV_HUGEPAGE);  // advice only: without huge pages the memory works the same
#endif
  return p;
}

void FreeBuffer::operator()(void* p) const {
  std::free(p);
}

}  // namespace detail

std::string to_text(const LString& s, const std::vector<std::string>& strings, std::size_t limit) {
  std::string out;
  std::size_t p = 0;
  const std::size_t n = limit ? std::min(limit, s.size()) : s.size();
  for (std::size_t m = 0; m < n; ++m) {
    const std::uint16_t w = s.symbols[m];
    const char c = symbol_of(w);
    out.push_back(c);
    const int k = count_of(w);
    if (k > 0) {
      out.push_back('(');
      for (int a = 0; a < k; ++a) {
        if (a) out.push_back(',');
        const float v = s.params[p + a];
        if (c == 'a' && a == 0 && v >= 0 && static_cast<std::size_t>(v) < strings.size())
          out += fmt::format("\"{}\"", strings[static_cast<std::size_t>(v)]);
        else
          out += fmt::format("{:g}", v);
      }
      out.push_back(')');
    }
    p += k;
  }
  return out;
}

std::vector<std::size_t> symbol_counts(const LString& s) {
  std::vector<std::size_t> counts(128, 0);
  for (std::size_t m = 0; m < s.size(); ++m) ++counts[static_cast<unsigned char>(symbol_of(s.symbols[m]))];
  return counts;
}

// `%` cuts off the rest of its branch (the reference's "Cut off remainder of branch"): the modules after it, up
// to its branch's ']' or the string's end, leave the string, so they neither grow nor hold memory. The `%`
// stays, so that the printed string shows where a branch was cut.
void cut_branches(LString& s) {
  const std::size_t n = s.size();
  std::uint16_t* sym = s.symbols.data();
  float* par = s.params.data();
  std::uint16_t* age = s.ages.size() == n ? s.ages.data() : nullptr;
  std::size_t w = 0, pr = 0, pw = 0;
  for (std::size_t r = 0; r < n;) {
    const std::uint16_t word = sym[r++];
    if (age) age[w] = age[r - 1];
    sym[w++] = word;
    for (int a = 0; a < count_of(word); ++a) par[pw++] = par[pr++];
    if (symbol_of(word) != '%') continue;
    for (int depth = 0; r < n; ++r) {
      const char c = symbol_of(sym[r]);
      if (c == ']' && depth == 0) break;
      depth += c == '[' ? 1 : c == ']' ? -1 : 0;
      pr += static_cast<std::size_t>(count_of(sym[r]));
    }
  }
  s.symbols.resize_discard(w);
  s.params.resize_discard(pw);
  if (age) s.ages.resize_discard(w);
}

Deriver::Deriver(const Grammar& grammar, DeriveSettings settings) : g_(grammar), s_(std::move(settings)) {
  auto cuts = [](const auto& modules) {
    return std::any_of(modules.begin(), modules.end(), [](const auto& m) { return m.symbol == '%'; });
  };
  has_cut_ = cuts(g_.premise) ||
             std::any_of(g_.rules.begin(), g_.rules.end(), [&](const Rule& r) { return cuts(r.successor); });
  for (int c = 0; c < 128; ++c) {
    const auto& list = g_.rules_for[c];
    if (list.empty()) continue;
    const Rule& r = g_.rules[list[0]];
    const bool unconditional =
        list.size() == 1 && !r.has_context && r.condition.empty() && r.probability.empty() && !g_.uses_age;
    const bool simple = unconditional && r.static_successor && !r.pred.has_parens;
    kind_[c] = simple ? 1 : unconditional && r.pred.has_parens ? 3 : 2;
    any_general_ |= kind_[c] == 2;
    static_symbols_[c] = static_cast<std::uint32_t>(r.successor.size());
    static_params_[c] = r.out_params;
    formals_[c] = static_cast<std::uint8_t>(r.pred.formals.size());
    lone_context_[c] = list.size() == 1 && r.has_context;
  }
  out_words_.resize(g_.rules.size());
  for (std::size_t ri = 0; ri < g_.rules.size(); ++ri)
    for (const auto& mod : g_.rules[ri].successor)
      out_words_[ri].push_back(
          static_cast<std::uint16_t>(encode(mod.symbol, static_cast<int>(mod.args.size())) | kNewFlag));
}

void Deriver::premise(LString& out) const {
  std::vector<std::uint16_t> syms;
  std::vector<float> pars;
  std::array<double, kMaxSlots> env = s_.env;
  env[kVarGeneration] = 0.0;
  for (std::size_t m = 0; m < g_.premise.size(); ++m) {
    const auto& mod = g_.premise[m];
    env[kVarIndex] = static_cast<double>(m);
    syms.push_back(static_cast<std::uint16_t>(encode(mod.symbol, static_cast<int>(mod.args.size())) | kNewFlag));
    for (const auto& a : mod.args) pars.push_back(static_cast<float>(a.eval(env.data(), *s_.host)));
  }
  out.symbols.assign(syms);
  out.params.assign(pars);
  if (g_.uses_age) {
    out.ages.resize_discard(syms.size());
    std::fill_n(out.ages.data(), syms.size(), std::uint16_t{0});
  }
  if (has_cut_) cut_branches(out);
}

// Matches the rule's contexts around module m (parameters at offset poff) and binds every formal.
bool Deriver::bind(const Rule& r, const LString& in, std::size_t m, std::size_t poff, double* env) const {
  const std::uint16_t* sym = in.symbols.data();
  const float* par = in.params.data();
  const std::size_t n = in.size();
  const int k = count_of(sym[m]);
  if (r.pred.has_parens && static_cast<std::size_t>(k) != r.pred.formals.size()) return false;
  std::size_t slot = 0;
  for (std::size_t a = 0; a < r.pred.formals.size(); ++a) env[kFormal0 + slot++] = par[poff + a];
  if (!r.has_context) return true;
  const bool flat = s_.brackets_transparent;

  // left context, right to left
  if (!r.left.empty()) {
    std::size_t left_slot = slot;
    for (const auto& p : r.left) left_slot += p.formals.size();
    std::ptrdiff_t pos = static_cast<std::ptrdiff_t>(m) - 1;
    std::size_t off = poff;
    for (std::size_t j = r.left.size(); j-- > 0;) {
      const Pattern& pat = r.left[j];
      char c = 0;
      std::uint16_t w = 0;
      while (true) {
        if (pos < 0) return false;
        w = sym[pos];
        c = symbol_of(w);
        off -= count_of(w);
        if (c == '[' || c == ']') {
          if (c == '[' && !flat && s_.left_in_branch) return false;  // left_context=branch: its branch's start ends it
          if (flat || c == '[') {                                    // '[' leads from a branch into its parent
            --pos;
            continue;
          }
          // ']' : skip the sibling branch that ends here
          int depth = 1;
          --pos;
          while (depth > 0) {
            if (pos < 0) return false;
            const std::uint16_t w2 = sym[pos];
            off -= count_of(w2);
            const char c2 = symbol_of(w2);
            if (c2 == ']')
              ++depth;
            else if (c2 == '[')
              --depth;
            --pos;
          }
          continue;
        }
        if (g_.ignore.test(static_cast<unsigned char>(c)) && c != pat.symbol) {
          --pos;
          continue;
        }
        break;
      }
      if (c != pat.symbol) return false;
      if (pat.has_parens && static_cast<std::size_t>(count_of(w)) != pat.formals.size()) return false;
      left_slot -= pat.formals.size();
      for (std::size_t a = 0; a < pat.formals.size(); ++a) env[kFormal0 + left_slot + a] = par[off + a];
      --pos;
    }
    for (const auto& p : r.left) slot += p.formals.size();
  }

  // right context, left to right
  if (!r.right.empty()) {
    std::size_t pos = m + 1;
    std::size_t off = poff + static_cast<std::size_t>(k);
    for (const Pattern& pat : r.right) {
      if (pat.symbol == ']') {  // skip the rest of the current branch, then consume its ']'
        int depth = 0;
        while (true) {
          if (pos >= n) return false;
          const char c = symbol_of(sym[pos]);
          if (c == '[')
            ++depth;
          else if (c == ']') {
            if (depth == 0) break;
            --depth;
          }
          off += count_of(sym[pos]);
          ++pos;
        }
        ++pos;
        continue;
      }
      char c = 0;
      std::uint16_t w = 0;
      while (true) {
        if (pos >= n) return false;
        w = sym[pos];
        c = symbol_of(w);
        if (c == pat.symbol) break;
        if (c == '[' || c == ']') {
          if (flat) {
            ++pos;
            continue;
          }
          if (c == ']') {  // the branch ends before the context does
            if (!s_.siblings) return false;
            // Context Includes Siblings: the context goes on in the next sibling branch (the next '[' of
            // the parent's string), skipping the parent's own symbols; none before the parent ends: no match.
            ++pos;
            while (true) {
              if (pos >= n) return false;
              const std::uint16_t w2 = sym[pos];
              const char c2 = symbol_of(w2);
              ++pos;
              if (c2 == '[') break;
              if (c2 == ']') return false;
              off += count_of(w2);
            }
            continue;
          }
          int depth = 1;  // skip a sub-branch
          ++pos;
          while (depth > 0) {
            if (pos >= n) return false;
            const std::uint16_t w2 = sym[pos];
            const char c2 = symbol_of(w2);
            if (c2 == '[')
              ++depth;
            else if (c2 == ']')
              --depth;
            off += count_of(w2);
            ++pos;
          }
          continue;
        }
        if (g_.ignore.test(static_cast<unsigned char>(c))) {
          off += count_of(w);
          ++pos;
          continue;
        }
        break;
      }
      if (c != pat.symbol) return false;
      if (pat.has_parens && static_cast<std::size_t>(count_of(w)) != pat.formals.size()) return false;
      for (std::size_t a = 0; a < pat.formals.size(); ++a) env[kFormal0 + slot + a] = par[off + a];
      slot += pat.formals.size();
      off += count_of(w);
      ++pos;
    }
  }
  return true;
}

// Most modules fail a context on their nearest neighbour. When that neighbour is neither a bracket nor
// ignored, bind's walk would stop at it and compare it with the pattern's symbol, so comparing it here
// decides the same without binding anything.
bool Deriver::neighbours_allow(const Rule& r, const LString& in, std::size_t m) const {
  const auto decides = [&](char c) { return c != '[' && c != ']' && !g_.ignore.test(static_cast<unsigned char>(c)); };
  if (!r.left.empty() && m > 0) {
    const char c = symbol_of(in.symbols[m - 1]);
    if (decides(c) && c != r.left.back().symbol) return false;
  }
  if (!r.right.empty() && r.right.front().symbol != ']' && m + 1 < in.size()) {
    const char c = symbol_of(in.symbols[m + 1]);
    if (decides(c) && c != r.right.front().symbol) return false;
  }
  return true;
}

int Deriver::choose(const LString& in, std::size_t m, std::size_t poff, double* env, int generation) const {
  const std::uint16_t w = in.symbols[m];
  const auto& list = g_.rules_for[static_cast<unsigned char>(symbol_of(w))];
  double psum = 0.0;
  int candidates[64];
  double weights[64];
  int ncand = 0;
  int fallback = -1;
  for (const std::uint16_t ri : list) {
    const Rule& r = g_.rules[ri];
    if (r.has_context && !neighbours_allow(r, in, m)) continue;
    if (!bind(r, in, m, poff, env)) continue;
    if (!r.condition.empty() && r.condition.eval(env, *s_.host) == 0.0) continue;
    if (r.probability.empty()) {
      fallback = ri;
      break;
    }
    double p = r.probability.eval(env, *s_.host);
    if (s_.units == ProbabilityUnits::Percent || (s_.units == ProbabilityUnits::Auto && p > 1.0)) p *= 0.01;
    if (!(p > 0.0)) continue;
    if (s_.probability == ProbabilityMode::Sequential) {
      if (draw(s_.seed, s_.stream, generation, m, ri) < p) return ri;
      continue;
    }
    if (ncand < 64) {
      candidates[ncand] = ri;
      weights[ncand++] = p;
      psum += p;
    }
  }
  if (ncand > 0) {
    const double u = draw(s_.seed, s_.stream, generation, m, 0xffff) * std::max(1.0, psum);
    double acc = 0.0;
    for (int k = 0; k < ncand; ++k) {
      acc += weights[k];
      if (u < acc) return candidates[k];
    }
  }
  return fallback;
}

void Deriver::rewrite(const LString& in, LString& out, int generation, const std::vector<TurtleVars>& states) {
  const std::size_t n = in.size();
  const std::size_t nb = block_count(n);
  const std::uint16_t* sym = in.symbols.data();
  const bool ages = g_.uses_age;
  const bool turtle = g_.uses_turtle && states.size() == n;
  if (any_general_) choice_.resize(n);
  block_in_params_.assign(nb + 1, 0);
  block_out_syms_.assign(nb + 1, 0);
  block_out_params_.assign(nb + 1, 0);

  // parameter offset of every block's first module
  if (in.params.size() > 0) {
    tbb::parallel_for(std::size_t{0}, nb, [&](std::size_t b) {
      std::size_t s = 0;
      const std::size_t end = std::min(n, (b + 1) * kBlock);
      for (std::size_t m = b * kBlock; m < end; ++m) s += static_cast<std::size_t>(count_of(sym[m]));
      block_in_params_[b + 1] = s;
    });
    for (std::size_t b = 0; b < nb; ++b) block_in_params_[b + 1] += block_in_params_[b];
  }

  auto setup_env = [&](double* env) {
    std::memcpy(env, s_.env.data(), sizeof(double) * kMaxSlots);
    env[kVarGeneration] = generation;
  };
  auto set_module_env = [&](double* env, std::size_t m) {
    env[kVarIndex] = static_cast<double>(m);
    if (ages) env[kVarAge] = in.ages[m];
    if (turtle) {
      const TurtleVars& t = states[m];
      env[kVarX] = t.x;
      env[kVarY] = t.y;
      env[kVarZ] = t.z;
      env[kVarArc] = t.arc;
      env[kVarLength] = t.length;
      env[kVarWidth] = t.width;
      env[kVarU] = t.u;
      env[kVarV] = t.v;
    }
  };

  // pass 1: choose and count
  tbb::parallel_for(std::size_t{0}, nb, [&](std::size_t b) {
    double env[kMaxSlots];
    setup_env(env);
    std::size_t osyms = 0, opars = 0, poff = block_in_params_[b];
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t m = b * kBlock; m < end; ++m) {
      const std::uint16_t w = sym[m];
      const unsigned c = w & kSymbolMask;
      const int k = count_of(w);
      switch (kind_[c]) {
        case 0:
          osyms += 1;
          opars += static_cast<std::size_t>(k);
          break;
        case 1:
          osyms += static_symbols_[c];
          opars += static_params_[c];
          break;
        case 3:
          if (k == formals_[c]) {
            osyms += static_symbols_[c];
            opars += static_params_[c];
          } else {
            osyms += 1;
            opars += static_cast<std::size_t>(k);
          }
          break;
        default: {
          if (lone_context_[c] && !neighbours_allow(g_.rules[g_.rules_for[c][0]], in, m)) {
            choice_[m] = kCopy;
            osyms += 1;
            opars += static_cast<std::size_t>(k);
            break;
          }
          set_module_env(env, m);
          const int r = choose(in, m, poff, env, generation);
          choice_[m] = r < 0 ? kCopy : static_cast<std::uint16_t>(r);
          if (r < 0) {
            osyms += 1;
            opars += static_cast<std::size_t>(k);
          } else {
            osyms += g_.rules[r].successor.size();
            opars += g_.rules[r].out_params;
          }
        }
      }
      poff += static_cast<std::size_t>(k);
    }
    block_out_syms_[b + 1] = osyms;
    block_out_params_[b + 1] = opars;
  });
  for (std::size_t b = 0; b < nb; ++b) {
    block_out_syms_[b + 1] += block_out_syms_[b];
    block_out_params_[b + 1] += block_out_params_[b];
  }
  const std::size_t total_syms = block_out_syms_[nb], total_pars = block_out_params_[nb];
  if (total_syms > s_.max_symbols)
    throw InputError(
        fmt::format("L-system runaway: generation {} would have {} symbols (from {}), over the limit "
                    "max_symbols={}; lower generations or raise max_symbols",
                    generation, total_syms, n, s_.max_symbols));
  if (total_pars > s_.max_params)
    throw InputError(fmt::format("L-system runaway: generation {} would have {} parameters, over the limit of {}",
                                 generation, total_pars, s_.max_params));
  out.symbols.resize_discard(total_syms);
  out.params.resize_discard(total_pars);
  if (ages)
    out.ages.resize_discard(total_syms);
  else
    out.ages.release();

  // pass 2: write
  tbb::parallel_for(std::size_t{0}, nb, [&](std::size_t b) {
    double env[kMaxSlots];
    setup_env(env);
    std::uint16_t* os = out.symbols.data() + block_out_syms_[b];
    float* op = out.params.data() + block_out_params_[b];
    std::uint16_t* oa = ages ? out.ages.data() + block_out_syms_[b] : nullptr;
    std::size_t poff = block_in_params_[b];
    const float* ip = in.params.data();
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    auto copy_module = [&](std::size_t m, std::uint16_t w, int k) {
      *os++ = static_cast<std::uint16_t>(w & ~kNewFlag);
      for (int a = 0; a < k; ++a) *op++ = ip[poff + a];
      if (oa) {
        const std::uint16_t age = in.ages[m];
        *oa++ = age == 0xffff ? age : static_cast<std::uint16_t>(age + 1);
      }
    };
    auto put_static = [&](const Rule& r, const std::vector<std::uint16_t>& words) {
      const std::size_t ns = words.size();
      os = std::copy(words.begin(), words.end(), os);  // an empty successor has no data() to memcpy from
      if (!r.static_params.empty()) {
        std::memcpy(op, r.static_params.data(), r.static_params.size() * sizeof(float));
        op += r.static_params.size();
      }
      if (oa) {
        std::fill_n(oa, ns, std::uint16_t{0});
        oa += ns;
      }
    };
    auto apply = [&](std::size_t m, std::uint16_t ri) {
      const Rule& r = g_.rules[ri];
      if (r.static_successor) {
        put_static(r, out_words_[ri]);
        return;
      }
      set_module_env(env, m);
      bind(r, in, m, poff, env);
      const std::uint16_t* words = out_words_[ri].data();
      for (const auto& mod : r.successor) {
        *os++ = *words++;
        for (const auto& a : mod.args) *op++ = static_cast<float>(a.eval(env, *s_.host));
        if (oa) *oa++ = 0;
      }
    };
    for (std::size_t m = b * kBlock; m < end; ++m) {
      const std::uint16_t w = sym[m];
      const unsigned c = w & kSymbolMask;
      const int k = count_of(w);
      switch (kind_[c]) {
        case 0:
          copy_module(m, w, k);
          break;
        case 1: {
          const std::uint16_t ri = g_.rules_for[c][0];
          put_static(g_.rules[ri], out_words_[ri]);
          break;
        }
        case 3:
          if (k == formals_[c])
            apply(m, g_.rules_for[c][0]);
          else
            copy_module(m, w, k);
          break;
        default: {
          const std::uint16_t ri = choice_[m];
          if (ri == kCopy)
            copy_module(m, w, k);
          else
            apply(m, ri);
        }
      }
      poff += static_cast<std::size_t>(k);
    }
  });
  if (has_cut_) cut_branches(out);
}

}  // namespace growbench::lsys
