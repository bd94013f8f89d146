// The npm lindenmayer peer of `make peers`: derives one case's string and prints one JSON line.
//   node lindenmayer.mjs CASE.json
// CASE.json is one L-system case of bench/peers/cases.json (scripts/peers writes growbench's grammar
// from the same object):
//   axiom        a string, or for parametric systems a list of modules [symbol, number...]
//   axiom_tail   optional [symbol, count]: appended count times (a long premise without a long file)
//   rules        {"a": "b"} string productions; "b<a": "b" is lindenmayer's classic context syntax;
//                {"A(l,w)": [["F", "l"], ["A", "l*0.9", "w"]]} is a parametric rule, compiled to the
//                function production a lindenmayer user writes by hand: ({part}) => { const [l, w] =
//                part.params; return [{symbol: 'F', params: [l]}, ...]; }
//   iterations   rewrites
//   warmup       untimed derivations first, each on a fresh LSystem (scripts/peers sets it from cases.json)
// The time covers iterate() alone, inside this process, like growbench's "derived in". The check fields
// are the module count and the SHA-256 of the symbols without parameters (getString()), which
// scripts/peers compares with growbench's string.
import { createHash } from 'node:crypto';
import { readFileSync } from 'node:fs';
import LSystem from 'lindenmayer';

function parametricProduction(params, modules) {
  const body = modules.map(([symbol, ...p]) => `{symbol: ${JSON.stringify(symbol)}, params: [${p.join(', ')}]}`);
  return new Function(`return ({ part }) => { const [${params.join(', ')}] = part.params; return [${body.join(', ')}]; };`)();
}

function build(spec) {
  let axiom = spec.axiom;
  const parametric = Array.isArray(axiom);
  if (parametric) axiom = axiom.map(([symbol, ...p]) => ({ symbol, params: p }));
  if (spec.axiom_tail) {
    const [symbol, count] = spec.axiom_tail;
    axiom = parametric ? axiom.concat(Array.from({ length: count }, () => ({ symbol, params: [] })))
                       : axiom + symbol.repeat(count);
  }
  const lsys = new LSystem({ axiom });
  for (const [from, to] of Object.entries(spec.rules)) {
    const m = /^(\w)\(([^)]*)\)$/.exec(from);
    if (m) lsys.setProduction(m[1], parametricProduction(m[2].split(',').map((s) => s.trim()), to));
    else lsys.setProduction(from, to);
  }
  return lsys;
}

const spec = JSON.parse(readFileSync(process.argv[2], 'utf8'));
for (let i = 0; i < (spec.warmup || 0); ++i) build(spec).iterate(spec.iterations);
const lsys = build(spec);
const t0 = process.hrtime.bigint();
const cpu0 = process.cpuUsage();
lsys.iterate(spec.iterations);
const cpu = process.cpuUsage(cpu0);
const seconds = Number(process.hrtime.bigint() - t0) / 1e9;
const symbols = lsys.getString();
const version = JSON.parse(readFileSync(new URL('./node_modules/lindenmayer/package.json', import.meta.url))).version;
console.log(JSON.stringify({
  peer: 'lindenmayer',
  version,
  node: process.version,
  seconds,
  cpu_seconds: (cpu.user + cpu.system) / 1e6,  // beside the wall time: a shared machine's load shows in the gap
  modules: lsys.axiom.length,
  sha256: createHash('sha256').update(symbols).digest('hex'),
}));
