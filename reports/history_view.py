"""The history page's interactive plot: per machine and suite, one metric at a time over the commits, a line per
cell relative to its first commit (log scale). Hovering a line names its cell, a point's tooltip gives its commit,
date and value, a filter keeps the cells whose names match, and clicking a commit lists every shown cell's value
there against the commit before, largest change first, as airspeed velocity's commit pages do. Change points
are drawn as diamonds. Plain SVG and a short script inside index.html: it works from file:// with nothing else.
"""

import html
import json
import math


def finite(v):
    return v if isinstance(v, (int, float)) and math.isfinite(v) else None


def group_html(key, commits, dates, files, data, change_points, metric_names):
    """One group's section. FILES: each commit's history file as a link from the page. DATA: {(cell, metric):
    [value or None per commit]}; CHANGE_POINTS: (cell, metric, index of the commit of the new level);
    METRIC_NAMES: {metric: words}."""
    metrics = sorted({m for _, m in data})
    payload = {
        "commits": commits, "dates": dates, "files": files,
        "metrics": [[m, metric_names.get(m, m)] for m in metrics],
        "series": {m: {c: [finite(v) for v in data[(c, mm)]] for c, mm in sorted(data) if mm == m} for m in metrics},
        "changes": [list(c) for c in change_points],
    }
    # No "<" inside the script element, which "</script>" or "<!--" in a name could end or derail.
    text = json.dumps(payload, allow_nan=False, separators=(",", ":")).replace("<", "\\u003c")
    e = html.escape
    options = "".join(f"<option value='{e(m)}'>{e(metric_names.get(m, m))}</option>" for m in metrics)
    return (f"<div class='gb-history' data-key='{e(key)}'><p><label>Metric <select class='gb-metric'>{options}"
            "</select></label> <label>Cells <input type='search' class='gb-filter' size='30' "
            "placeholder='filter by name'></label> <span class='note'>wheel: zoom, drag: pan, double-click: all "
            "commits</span> <span class='gb-hover'></span></p>"
            "<svg class='gb-plot' width='900' height='420' role='img' aria-label='each cell over the commits'></svg>"
            "<div class='gb-commit'><p class='note'>Click a point for that commit's values.</p></div>"
            f"<script type='application/json' class='gb-data'>{text}</script></div>")


STYLE = """
.gb-history .gb-plot path.gb-line { fill: none; stroke-width: 1.2; opacity: 0.8; }
.gb-history .gb-plot g.gb-cell.hot path.gb-line { stroke-width: 3; opacity: 1; }
.gb-history .gb-plot g.gb-cell.cold { opacity: 0.15; }
.gb-history .gb-hover { font-weight: bold; }
.gb-history td.up { color: #b00; } .gb-history td.down { color: #070; }
"""

SCRIPT = r"""
(function () {
  var palette = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#e377c2', '#17becf', '#bcbd22', '#7f7f7f'];
  function tickText(t) { return String(+t.toPrecision(4)); }
  function fmt(v) { return v === null || v === undefined ? 'n/a' : String(+v.toPrecision(5)); }
  document.querySelectorAll('.gb-history').forEach(function (box) {
    var D = JSON.parse(box.querySelector('.gb-data').textContent);
    var svg = box.querySelector('.gb-plot'), NS = svg.namespaceURI;
    var metricBox = box.querySelector('.gb-metric'), filterBox = box.querySelector('.gb-filter');
    var hover = box.querySelector('.gb-hover'), panel = box.querySelector('.gb-commit');
    function el(tag, attrs, parent) {
      var e = document.createElementNS(NS, tag);
      for (var k in attrs) e.setAttribute(k, attrs[k]);
      parent.appendChild(e);
      return e;
    }
    function cells() {
      var words = filterBox.value.toLowerCase().split(/\s+/).filter(Boolean);
      return Object.keys(D.series[metricBox.value] || {}).filter(function (c) {
        return words.every(function (w) { return c.toLowerCase().indexOf(w) >= 0; });
      });
    }
    function first(vals) { for (var i = 0; i < vals.length; i++) if (vals[i] > 0) return vals[i]; return null; }
    function showCommit(i) {
      var m = metricBox.value, rows = [];
      cells().forEach(function (c) {
        var v = D.series[m][c], prev = null;
        for (var j = i - 1; j >= 0; j--) if (v[j] > 0) { prev = v[j]; break; }
        rows.push([c, v[i], prev, v[i] > 0 && prev ? v[i] / prev : null]);
      });
      rows.sort(function (a, b) {
        var x = a[3] === null ? 0 : Math.abs(Math.log(a[3])), y = b[3] === null ? 0 : Math.abs(Math.log(b[3]));
        return y - x;
      });
      panel.textContent = '';
      var h = document.createElement('h3');
      h.textContent = 'Commit ' + D.commits[i] + (D.dates[i] ? ' (' + D.dates[i] + ')' : '') + ': ' +
        metricBox.options[metricBox.selectedIndex].text +
        (i > 0 ? ', against the commit before with a value' : '');
      panel.appendChild(h);
      var t = document.createElement('table');
      t.className = 'gb-commit-table';
      var head = t.insertRow();
      ['cell', 'value', 'before', 'ratio'].forEach(function (x) { var th = document.createElement('th'); th.textContent = x; head.appendChild(th); });
      rows.forEach(function (r) {
        var tr = t.insertRow();
        tr.dataset.cell = r[0];
        [r[0], fmt(r[1]), fmt(r[2]), r[3] === null ? 'n/a' : r[3].toFixed(3)].forEach(function (x, k) {
          var td = tr.insertCell();
          td.textContent = x;
          if (k === 3 && r[3] !== null) td.className = r[3] > 1.005 ? 'up' : r[3] < 0.995 ? 'down' : '';
        });
      });
      panel.appendChild(t);
      var p = document.createElement('p'), link = document.createElement('a');
      link.href = D.files[i];
      link.textContent = D.files[i];
      link.className = 'gb-file';
      p.append('Every run of this commit, cell by cell: ', link);
      panel.appendChild(p);
      box.dataset.commit = D.commits[i];
    }
    // The commits shown: [a, b] in commit indices; the wheel zooms about the pointer, a drag pans.
    var n = D.commits.length, a = 0, b = Math.max(n - 1, 1), W = 900, H = 420, L = 60, R = 20, T = 10, B = 70;
    function inView(i) { return i >= a - 1e-9 && i <= b + 1e-9; }
    svg.addEventListener('wheel', function (ev) {
      ev.preventDefault();
      var at = a + (ev.offsetX - L) / (W - L - R) * (b - a);
      var w = Math.min(Math.max(n - 1, 1), Math.max(2, (b - a) * (ev.deltaY > 0 ? 1.25 : 0.8)));
      a = at - (at - a) * w / (b - a);
      a = Math.max(0, Math.min(a, Math.max(n - 1, 1) - w));
      b = a + w;
      draw();
    }, {passive: false});
    var dragFrom = null;
    svg.addEventListener('mousedown', function (ev) { dragFrom = [ev.clientX, a, b]; });
    window.addEventListener('mouseup', function () { dragFrom = null; });
    svg.addEventListener('mousemove', function (ev) {
      if (!dragFrom || !(ev.buttons & 1)) return;
      var w = dragFrom[2] - dragFrom[1], shift = -(ev.clientX - dragFrom[0]) / (W - L - R) * w;
      a = Math.max(0, Math.min(dragFrom[1] + shift, Math.max(n - 1, 1) - w));
      b = a + w;
      draw();
    });
    svg.addEventListener('dblclick', function () { a = 0; b = Math.max(n - 1, 1); draw(); });
    function draw() {
      svg.textContent = '';
      var m = metricBox.value, shown = cells();
      box.dataset.window = a.toFixed(2) + '..' + b.toFixed(2);
      var lo = Infinity, hi = -Infinity;
      shown.forEach(function (c) {
        var v = D.series[m][c], f = first(v);
        v.forEach(function (x, i) { if (x > 0 && inView(i)) { lo = Math.min(lo, x / f); hi = Math.max(hi, x / f); } });
      });
      box.dataset.lines = shown.length;
      if (!shown.length) { el('text', {x: L, y: 30}, svg).textContent = 'No cell matches the filter.'; return; }
      lo = Math.min(lo, 0.98) / 1.03; hi = Math.max(hi, 1.02) * 1.03;  // every point whole inside the frame
      if (!(lo <= hi)) { lo = 1; hi = 1; }
      var sx = function (i) { return L + (n > 1 ? (i - a) / (b - a) : 0.5) * (W - L - R); };
      var sy = function (r) { return T + (Math.log(hi) - Math.log(r)) / (Math.log(hi) - Math.log(lo)) * (H - T - B); };
      var clip = el('clipPath', {id: 'gb-clip-' + box.dataset.key.replace(/[^A-Za-z0-9]/g, '_')}, el('defs', {}, svg));
      el('rect', {x: L - 8, y: 0, width: W - L - R + 16, height: H - B + 8}, clip);
      el('rect', {x: L, y: T, width: W - L - R, height: H - T - B, fill: '#fff', stroke: '#999'}, svg);
      var step = Math.max(1, Math.ceil((b - a + 1) / 30));
      D.commits.forEach(function (c, i) {
        if (i % step || !inView(i)) return;
        var x = sx(i);
        el('line', {x1: x, x2: x, y1: H - B, y2: H - B + 4, stroke: '#333'}, svg);
        el('text', {x: x, y: H - B + 8, 'font-size': 10, transform: 'rotate(60 ' + x + ' ' + (H - B + 8) + ')'}, svg).textContent = c.slice(0, 8);
      });
      var span = Math.log10(hi / lo), ts = [];
      [0.5, 0.8, 0.9, 0.95, 0.98, 1, 1.02, 1.05, 1.1, 1.2, 1.5, 2, 3, 5, 10].forEach(function (t) { if (t >= lo && t <= hi) ts.push(t); });
      if (span > 1.2) { ts = []; for (var p = Math.ceil(Math.log10(lo)); p <= Math.floor(Math.log10(hi)); p++) ts.push(Math.pow(10, p)); }
      ts.forEach(function (t) {
        el('line', {x1: L, x2: W - R, y1: sy(t), y2: sy(t), stroke: t === 1 ? '#888' : '#e4e4e4'}, svg);
        el('text', {x: L - 6, y: sy(t) + 4, 'font-size': 11, 'text-anchor': 'end'}, svg).textContent = tickText(t);
      });
      el('text', {x: 14, y: (T + H - B) / 2, 'font-size': 12, 'text-anchor': 'middle',
                  transform: 'rotate(-90 14 ' + (T + H - B) / 2 + ')'}, svg).textContent = "value / the cell's first";
      shown.forEach(function (c, k) {
        var v = D.series[m][c], f = first(v), colour = palette[k % palette.length];
        var g = el('g', {class: 'gb-cell', 'data-cell': c, 'clip-path': 'url(#' + clip.id + ')'}, svg), d = '';
        v.forEach(function (x, i) {
          if (x > 0 && i >= Math.floor(a) && i <= Math.ceil(b)) d += (d ? 'L' : 'M') + sx(i).toFixed(1) + ',' + sy(x / f).toFixed(1);
        });
        el('path', {d: d, class: 'gb-line', stroke: colour}, g);
        v.forEach(function (x, i) {
          if (!(x > 0) || !inView(i)) return;
          var change = D.changes.some(function (ch) { return ch[0] === c && ch[1] === m && ch[2] === i; });
          var p = change ? el('path', {d: 'M' + sx(i) + ',' + (sy(x / f) - 7) + 'l7,7l-7,7l-7,-7z', fill: '#fff',
                                       stroke: colour, 'stroke-width': 2, class: 'gb-point gb-change'}, g)
                         : el('circle', {cx: sx(i), cy: sy(x / f), r: 3, fill: colour, class: 'gb-point'}, g);
          p.setAttribute('data-commit', i);
          p.style.cursor = 'pointer';
          el('title', {}, p).textContent = c + '\n' + D.commits[i] + (D.dates[i] ? ' (' + D.dates[i] + ')' : '') +
            '\n' + fmt(x) + ' (' + (x / f).toFixed(3) + ' of its first)' + (change ? '\na change point: a new level from here' : '');
          p.addEventListener('click', function () { showCommit(i); });
        });
        g.addEventListener('mouseenter', function () {
          svg.querySelectorAll('g.gb-cell').forEach(function (o) { o.classList.toggle('cold', o !== g); });
          g.classList.add('hot');
          hover.textContent = c;
        });
        g.addEventListener('mouseleave', function () {
          svg.querySelectorAll('g.gb-cell').forEach(function (o) { o.classList.remove('cold', 'hot'); });
          hover.textContent = '';
        });
      });
    }
    metricBox.addEventListener('change', draw);
    filterBox.addEventListener('input', draw);
    draw();
  });
  document.body.setAttribute('data-history', 'ready');
})();
"""
