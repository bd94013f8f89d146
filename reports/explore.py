"""The report's interactive part: every trial in a table that sorts and filters, and a quality-against-cost plot
whose points open the trials' pages. Plain HTML and SVG with a short script inside index.html, so it works
from file:// with nothing else loaded. The data is the cells' own numbers, embedded as JSON.

Each point and row is one trial cell: its growth time is the median over its repetitions the suite wrote
(Cell.growth_median; one trial when there is one), its metrics the cell's. A plant judged other than valid is drawn hollow and grey and said so:
it is shown, never compared as a result.
"""

import html
import json
import math
import statistics

# Cost axes: (key, label, log scale by default).
COSTS = [("growth_s", "growth time (s, median over repetitions)", True),
         ("nodes", "nodes", True),
         ("glb", "plant.glb (bytes)", True),
         ("growth_peak_mb", "growth phase's peak memory (MiB)", True)]


def number(v):
    """V if it is a finite number, else None (n/a)."""
    ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
    return v if ok else None


def trial_row(c, page):
    peaks = [p for p in c.growth_rss if number(p) is not None]
    params = c.t.get("params") if isinstance(c.t.get("params"), dict) else {}
    return {"id": c.id(), "page": page, "entry": c.row, "label": c.label, "scene": c.scene,
            "seed": c.seed, "status": c.status,
            "sweep": {k: v for k, v in (c.t.get("sweep") or {}).items() if isinstance(v, (str, bool)) or number(v) is not None}
                     if isinstance(c.t.get("sweep"), dict) else {},
            "params": {k: v for k, v in params.items() if isinstance(v, (str, bool)) or number(v) is not None},
            "verdict": c.verdict or ("valid" if c.ok else "-"), "valid": bool(c.valid),
            "reasons": "; ".join(c.reasons), "trials": len(c.growth),
            "growth_s": number(c.growth_median()) if c.growth else None, "nodes": c.nodes or None, "glb": number(c.bytes.get("glb")),
            "growth_peak_mb": statistics.median(peaks) / 2 ** 20 if peaks else None,
            "metrics": {k: number(v) for k, v in sorted(c.metrics.items()) if not isinstance(v, (list, dict))}}


def explore_html(cells, pages, quality):
    """The section's HTML. QUALITY: report.py's (key, label, unit) of the quality metrics, offered first."""
    rows = [trial_row(c, pages.get(c.id())) for c in cells]
    metrics = sorted({k for r in rows for k, v in r["metrics"].items() if v is not None})
    known = [(k, label) for k, label, _ in quality if k in metrics]
    ys = known + [(k, k) for k in metrics if k not in dict(known)]
    data = {"rows": rows, "costs": [list(c) for c in COSTS] + [[k, label, False] for k, label in ys],
            "metrics": [list(m) for m in ys]}
    # No "<" inside the script element, which "</script>" or "<!--" in a name could end or derail.
    text = json.dumps(data, allow_nan=False, separators=(",", ":")).replace("<", "\\u003c")
    e = html.escape
    options = lambda items: "".join(f"<option value='{e(k)}'>{e(label)}</option>" for k, label, *_ in items)
    choices = lambda key, what: (f"<label>{what} <select class='gb-choice' data-key='{key}'><option value=''>all</option>" +
                                 options((v, v) for v in sorted({str(r[key]) for r in rows})) + "</select></label> ")
    return f"""<h2 id='explore'>Explore the trials</h2>
<p class='note'>Every trial cell (entry, scene, seed): its growth time is the median over its repetitions. Click a
column to sort, type to filter (every word must match the entry, scene, seed, verdict or id), click a point or a
row's id for the trial's page (its render, 3D view and files). Hollow grey points are plants judged degenerate or
not applicable: shown, not compared.</p>
<div id='gb-explore'>
<p>{choices("label", "Algorithm entry")}{choices("scene", "scene")}{choices("verdict", "verdict")}
<label>words <input type='search' id='gb-filter' size='30' placeholder='e.g. ivy bunny'></label>
<span id='gb-count'></span></p>
<p><label>Quality <select id='gb-y'>{options(ys)}</select></label>
<label>against <select id='gb-x'>{options(COSTS)}<optgroup label='or another metric'>{options(ys)}</optgroup></select></label>
<label><input type='checkbox' id='gb-logx' checked> log scale</label></p>
<svg id='gb-plot' width='760' height='440' role='img' aria-label='quality against cost, a point per trial'></svg>
<div class='wide'><table class='results' id='gb-trials'><thead><tr></tr></thead><tbody></tbody></table></div>
</div>
<script type='application/json' id='gb-explore-data'>{text}</script>
<script>{EXPLORE_SCRIPT}</script>"""


EXPLORE_SCRIPT = r"""
(function () {
  var D = JSON.parse(document.getElementById('gb-explore-data').textContent);
  var NS = document.getElementById('gb-plot').namespaceURI;  // SVG's, as the HTML parser gave the <svg>
  var cols = [['id', 'trial'], ['entry', 'entry'], ['scene', 'scene'], ['seed', 'seed'], ['verdict', 'verdict'],
              ['trials', 'repetitions'], ['growth_s', 'growth (s)'], ['nodes', 'nodes'], ['glb', 'plant.glb (B)']];
  D.metrics.forEach(function (m) { cols.push(['m:' + m[0], m[0]]); });
  var sortKey = 'id', sortDir = 1, filter = [];
  var entries = [];
  D.rows.forEach(function (r) { if (entries.indexOf(r.entry) < 0) entries.push(r.entry); });
  var palette = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#e377c2', '#17becf', '#bcbd22', '#7f7f7f'];
  function colour(entry) { return palette[entries.indexOf(entry) % palette.length]; }
  function value(r, k) { return k.slice(0, 2) === 'm:' ? r.metrics[k.slice(2)] : r[k]; }
  function costOf(r, k) { return k in r.metrics ? r.metrics[k] : r[k]; }  // an x axis: a cost or a metric
  function paramsText(r) {
    var keys = Object.keys(r.sweep).length ? Object.keys(r.sweep) : Object.keys(r.params);
    return keys.map(function (k) { return k + '=' + JSON.stringify(k in r.sweep ? r.sweep[k] : r.params[k]); }).join(' ');
  }
  function text(v) {
    if (v === null || v === undefined) return 'n/a';
    if (typeof v === 'number') return Number.isInteger(v) ? String(v) : v.toPrecision(4);
    return String(v);
  }
  function shown() {
    var picked = {};
    document.querySelectorAll('#gb-explore select.gb-choice').forEach(function (s) { if (s.value) picked[s.dataset.key] = s.value; });
    return D.rows.filter(function (r) {
      for (var k in picked) if (String(r[k]) !== picked[k]) return false;
      var hay = (r.id + ' ' + r.entry + ' ' + r.scene + ' s' + r.seed + ' ' + r.verdict).toLowerCase();
      return filter.every(function (w) { return hay.indexOf(w) >= 0; });
    });
  }
  function compare(a, b) {
    var x = value(a, sortKey), y = value(b, sortKey);
    var xn = x === null || x === undefined, yn = y === null || y === undefined;
    if (xn || yn) return xn === yn ? 0 : xn ? 1 : -1;  // n/a last, whichever the direction
    return (typeof x === 'number' && typeof y === 'number' ? x - y : String(x).localeCompare(String(y))) * sortDir;
  }
  function el(tag, attrs, parent, ns) {
    var e = ns ? document.createElementNS(NS, tag) : document.createElement(tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function table(rows) {
    var head = document.querySelector('#gb-trials thead tr'), body = document.querySelector('#gb-trials tbody');
    head.textContent = '';
    cols.forEach(function (c) {
      var th = el('th', {'data-key': c[0], title: 'sort by ' + c[1]}, head);
      th.textContent = c[1] + (c[0] === sortKey ? (sortDir > 0 ? ' \u25b2' : ' \u25bc') : '');
      th.style.cursor = 'pointer';
      th.addEventListener('click', function () {
        sortDir = sortKey === c[0] ? -sortDir : 1;
        sortKey = c[0];
        draw();
      });
    });
    body.textContent = '';
    rows.slice().sort(compare).forEach(function (r) {
      var tr = el('tr', {'data-id': r.id}, body);
      if (!r.valid) tr.className = 'left-out-row';
      cols.forEach(function (c) {
        var td = el('td', {}, tr);
        if (c[0] === 'id' && r.page) { var a = el('a', {href: r.page}, td); a.textContent = r.id; }
        else td.textContent = text(value(r, c[0]));
        if (c[0] === 'verdict' && r.reasons) td.title = r.reasons;
      });
    });
  }
  function tickText(t) { return String(+t.toPrecision(6)); }
  function ticks(lo, hi, log) {
    var out = [];
    if (log) {  // decades, and 2 and 5 times them over a short range
      var few = Math.log10(hi / lo) < 2.5;
      for (var p = Math.floor(Math.log10(lo)); p <= Math.ceil(Math.log10(hi)); p++)
        (few ? [1, 2, 5] : [1]).forEach(function (m) { out.push(+(m * Math.pow(10, p)).toPrecision(6)); });
      return out.filter(function (t) { return t >= lo * 0.999 && t <= hi * 1.001; });
    }
    var step = Math.pow(10, Math.floor(Math.log10((hi - lo) / 4 || 1)));
    if ((hi - lo) / step > 10) step *= 2;
    if ((hi - lo) / step > 10) step *= 2.5;
    for (var t = Math.ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) out.push(+t.toPrecision(12));
    return out;
  }
  function plot(rows) {
    var svg = document.getElementById('gb-plot');
    svg.textContent = '';
    var xk = document.getElementById('gb-x').value, yk = document.getElementById('gb-y').value;
    if (!yk) {
      el('text', {x: 20, y: 30, 'font-size': 12, id: 'gb-plot-note'}, svg, true).textContent =
        'No trial has a quality metric to plot.';
      return;
    }
    var cost = D.costs.filter(function (c) { return c[0] === xk; })[0];
    var yLabel = (D.metrics.filter(function (m) { return m[0] === yk; })[0] || [yk, yk])[1];
    var log = document.getElementById('gb-logx').checked;
    var pts = rows.filter(function (r) {
      var x = costOf(r, xk), y = r.metrics[yk];
      return typeof x === 'number' && typeof y === 'number' && (!log || x > 0);
    });
    var W = 760, H = 440, L = 70, R = 190, T = 14, B = 50;
    var missing = rows.length - pts.length;
    var note = el('text', {x: L, y: H - 4, 'font-size': 11, fill: '#555', id: 'gb-plot-note'}, svg, true);
    note.textContent = pts.length + ' of ' + rows.length + ' trials drawn' +
      (missing ? ' (' + missing + ' have no ' + yLabel + ' or no ' + cost[1] + (log ? ', or a cost of 0 on a log axis' : '') + ')' : '');
    if (!pts.length) return;
    var xs = pts.map(function (r) { return costOf(r, xk); }), ysv = pts.map(function (r) { return r.metrics[yk]; });
    var x0 = Math.min.apply(null, xs), x1 = Math.max.apply(null, xs);
    var y0 = Math.min(0, Math.min.apply(null, ysv)), y1 = Math.max.apply(null, ysv);
    if (log) { x0 /= 1.3; x1 *= 1.3; } else { var px = (x1 - x0) * 0.05 || 1; x0 -= px; x1 += px; }
    if (y1 === y0) y1 = y0 + 1;
    y1 += 0.04 * (y1 - y0);  // the highest point whole inside the frame
    var f = function (v) { return log ? Math.log10(v) : v; };
    var sx = function (v) { return L + (f(v) - f(x0)) / (f(x1) - f(x0)) * (W - L - R); };
    var sy = function (v) { return H - B - (v - y0) / (y1 - y0) * (H - T - B); };
    el('rect', {x: L, y: T, width: W - L - R, height: H - T - B, fill: 'none', stroke: '#999'}, svg, true);
    ticks(x0, x1, log).forEach(function (t) {
      el('line', {x1: sx(t), x2: sx(t), y1: H - B, y2: H - B + 5, stroke: '#333'}, svg, true);
      var lab = el('text', {x: sx(t), y: H - B + 17, 'font-size': 11, 'text-anchor': 'middle'}, svg, true);
      lab.textContent = tickText(t);
    });
    ticks(y0, y1, false).forEach(function (t) {
      el('line', {x1: L - 5, x2: L, y1: sy(t), y2: sy(t), stroke: '#333'}, svg, true);
      var lab = el('text', {x: L - 8, y: sy(t) + 4, 'font-size': 11, 'text-anchor': 'end'}, svg, true);
      lab.textContent = tickText(t);
    });
    el('text', {x: (L + W - R) / 2, y: H - B + 33, 'font-size': 12, 'text-anchor': 'middle'}, svg, true).textContent =
      cost[1] + (log ? ', log scale' : '');
    el('text', {x: 14, y: (T + H - B) / 2, 'font-size': 12, 'text-anchor': 'middle',
                transform: 'rotate(-90 14 ' + (T + H - B) / 2 + ')'}, svg, true).textContent = yLabel;
    pts.forEach(function (r) {
      var a = el('a', {href: r.page || '#', class: 'gb-point', 'data-id': r.id}, svg, true);
      var c = el('circle', {cx: sx(costOf(r, xk)), cy: sy(r.metrics[yk]), r: 5,
                            fill: r.valid ? colour(r.entry) : 'none', stroke: r.valid ? '#222' : '#888',
                            'stroke-width': r.valid ? 0.5 : 1.5}, a, true);
      el('title', {}, c, true).textContent = r.id + (r.valid ? '' : ' (' + r.verdict + ': not compared)') + '\n' +
        yLabel + ' ' + text(r.metrics[yk]) + ', ' + cost[1] + ' ' + text(costOf(r, xk)) + ' (' + r.trials + ' repetitions)' +
        '\n' + (Object.keys(r.sweep).length ? 'swept: ' : 'parameters: ') + paramsText(r);
    });
    entries.forEach(function (entry, i) {
      var y = T + 12 + 16 * i;
      el('circle', {cx: W - R + 16, cy: y - 4, r: 5, fill: colour(entry)}, svg, true);
      el('text', {x: W - R + 26, y: y, 'font-size': 11}, svg, true).textContent = entry;
    });
    var y = T + 12 + 16 * entries.length;
    el('circle', {cx: W - R + 16, cy: y - 4, r: 5, fill: 'none', stroke: '#888', 'stroke-width': 1.5}, svg, true);
    el('text', {x: W - R + 26, y: y, 'font-size': 11}, svg, true).textContent = 'not valid: not compared';
  }
  function draw() {
    var rows = shown();
    document.getElementById('gb-count').textContent = rows.length + ' of ' + D.rows.length + ' trial cells';
    table(rows);
    plot(rows);
  }
  document.getElementById('gb-filter').addEventListener('input', function (ev) {
    filter = ev.target.value.toLowerCase().split(/\s+/).filter(Boolean);
    draw();
  });
  ['gb-y', 'gb-logx'].forEach(function (id) { document.getElementById(id).addEventListener('change', draw); });
  document.querySelectorAll('#gb-explore select.gb-choice').forEach(function (s) { s.addEventListener('change', draw); });
  document.getElementById('gb-x').addEventListener('change', function () {
    var x = document.getElementById('gb-x').value;
    document.getElementById('gb-logx').checked = D.costs.filter(function (c) { return c[0] === x; })[0][2];
    draw();
  });
  draw();
  document.body.setAttribute('data-explore', 'ready');
})();
"""


def growth_curve_svg(curve, width=520, height=220):
    """A trial's nodes over its growth steps (its record's growth curve) as an inline SVG, or "" without one."""
    steps, nodes = (curve or {}).get("step") or [], (curve or {}).get("nodes") or []
    pts = [(s, n) for s, n in zip(steps, nodes) if number(s) is not None and number(n) is not None]
    if len(pts) < 2:
        return ""
    L, R, T, B = 56, 12, 10, 36
    s1, n1 = max(s for s, _ in pts) or 1, max(n for _, n in pts) or 1
    sx = lambda s: L + s / s1 * (width - L - R)
    sy = lambda n: height - B - n / n1 * (height - T - B)
    path = "M" + "L".join(f"{sx(s):.1f},{sy(n):.1f}" for s, n in pts)
    ticks = "".join(f"<text x='{L - 6}' y='{sy(v) + 4:.1f}' font-size='11' text-anchor='end'>{v:g}</text>"
                    for v in (0, n1))
    ticks += "".join(f"<text x='{sx(v):.1f}' y='{height - B + 15}' font-size='11' text-anchor='middle'>{v:g}</text>"
                     for v in (0, s1))
    return (f"<svg width='{width}' height='{height}' role='img' aria-label='nodes over growth steps'>"
            f"<rect x='{L}' y='{T}' width='{width - L - R}' height='{height - T - B}' fill='none' stroke='#999'/>"
            f"<path d='{path}' fill='none' stroke='#2a6f2a' stroke-width='1.5'/>{ticks}"
            f"<text x='{(L + width - R) / 2}' y='{height - 4}' font-size='12' text-anchor='middle'>growth step</text>"
            f"<text x='14' y='{(T + height - B) / 2}' font-size='12' text-anchor='middle' "
            f"transform='rotate(-90 14 {(T + height - B) / 2})'>nodes</text></svg>")
