// isolink report.html: draws a run, a sweep, a pack or a stress run from the JSON block #isolink-data with
// dygraphs (inlined beside this script). Nothing is fetched: the page opens offline. When every
// plot has drawn, the body gets data-ready="1".
(function () {
  'use strict';
  const data = JSON.parse(document.getElementById('isolink-data').textContent);
  const app = document.getElementById('app');
  const kind = document.body.dataset.kind;
  let pending = 0;  // plots and images still drawing
  // Every plot, for scripting and for the browser test (tests/reports/html_browser_test.py):
  // {kind: 'wave' | 'margin', graph: the Dygraph, ...}.
  const plots = window.isolinkPlots = [];
  function waitFor() { ++pending; let done = false;
    return function () { if (done) return; done = true; if (--pending === 0) ready(); }; }
  function ready() { document.body.dataset.ready = '1'; }

  // --- DOM helpers ---
  function el(tag, attrs, children) {
    const e = document.createElement(tag);
    for (const k in attrs || {}) {
      if (k === 'text') e.textContent = attrs[k];
      else if (k === 'cls') e.className = attrs[k];
      else if (k.startsWith('on')) e.addEventListener(k.slice(2), attrs[k]);
      else e.setAttribute(k, attrs[k]);
    }
    for (const c of children || []) if (c != null) e.append(c);
    return e;
  }
  function section(title, id) {
    const s = el('section', id ? {id: id} : {}, [el('h2', {text: title})]);
    app.append(s);
    return s;
  }
  function table(head, rows, opts) {
    const t = el('table', {cls: (opts && opts.cls) || ''});
    t.append(el('thead', {}, [el('tr', {}, head.map(h => el('th', {text: h})))]));
    const tb = el('tbody');
    for (const r of rows) tb.append(el('tr', r.attrs || {}, r.cells.map(c =>
      c instanceof Node ? el('td', {}, [c]) : el('td', {text: c == null ? '-' : String(c)}))));
    t.append(tb);
    return t;
  }
  function fmt(x, digits) {
    if (x == null || !isFinite(x)) return '-';
    // Trailing zeros after a decimal point only: 2000 stays 2000, 2.500 is 2.5, 1.000e+3 1e+3.
    return Number(x).toPrecision(digits || 4).replace(/(\.\d*?)0+(e|$)/, '$1$2').replace(/\.(e|$)/, '$1');
  }
  function signed(x, digits) { return x == null || !isFinite(x) ? '-' : (x >= 0 ? '+' : '') + fmt(x, digits); }
  // A long text (a whole stack read's decoded bytes or traffic) cut to its first `max` characters,
  // saying how much is left out and where it is: uncut, a 2,000-frame record's would push the
  // waveforms 10,000 pixels down the page.
  function clipText(s, max, where) {
    if (!s || s.length <= max) return s;
    return s.slice(0, max) + ' ... (' + (s.length - max) + ' more characters: ' + where + ')';
  }
  // Seconds with an SI prefix ("12.5 us").
  function si(x, unit) {
    if (x == null || !isFinite(x)) return '-';
    const a = Math.abs(x);
    const p = a >= 1 || a === 0 ? ['', 1] : a >= 1e-3 ? ['m', 1e3] : a >= 1e-6 ? ['u', 1e6] :
      a >= 1e-9 ? ['n', 1e9] : ['p', 1e12];
    return fmt(x * p[1], 4) + ' ' + p[0] + unit;
  }
  function verdictBadge(v, id) {
    const t = String(v || '-');
    const a = {cls: 'badge ' + (t === 'pass' ? 'pass' : t === 'fail' ? 'fail' : 'other'),
               text: t === 'pass' ? 'PASS' : t === 'fail' ? 'FAIL' : t.toUpperCase()};
    if (id) a.id = id;
    return el('span', a);
  }
  function copyButton(text) {
    const b = el('button', {cls: 'copy', type: 'button', text: 'copy'});
    b.addEventListener('click', () => {
      const done = () => { b.textContent = 'copied'; setTimeout(() => { b.textContent = 'copy'; }, 1500); };
      if (navigator.clipboard && window.isSecureContext)
        navigator.clipboard.writeText(text).then(done, () => fallback());
      else fallback();
      function fallback() {
        const ta = el('textarea', {}, []); ta.value = text; document.body.append(ta);
        ta.select(); try { document.execCommand('copy'); done(); } catch (e) {} ta.remove();
      }
    });
    return b;
  }
  function image(src, alt) {
    const done = waitFor();
    const img = el('img', {src: src, alt: alt, cls: 'figure'});
    img.addEventListener('load', done);
    img.addEventListener('error', done);
    if (img.complete) done();
    return img;
  }
  function decode(b64, Type) {
    const bin = atob(b64);
    const u8 = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; ++i) u8[i] = bin.charCodeAt(i);
    return new Type(u8.buffer);
  }

  // --- the waveform plot: full resolution zoomed in, min/max buckets zoomed out ---
  const kBuckets = 2000;
  function wavePlot(host, wave, check, vth) {
    const v = decode(wave.v, Float32Array);
    const n = v.length;
    let t;
    if (wave.t || wave.t64) { const off = wave.t ? decode(wave.t, Float32Array) : decode(wave.t64, Float64Array); t = new Float64Array(n); for (let i = 0; i < n; ++i) t[i] = wave.t0 + off[i]; }
    else { t = new Float64Array(n); for (let i = 0; i < n; ++i) t[i] = wave.t0 + i * wave.dt; t[n - 1] = wave.t_last; }
    const pulses = (check && check.pulses) || [];
    const frames = (check && check.decoded && check.decoded.frames) || [];
    const failing = pulses.filter(p => p.fails && p.fails.length);
    // Failing intervals: from one tenth of a half bit before the start crossing to the end.
    const bad = failing.map(p => [p.start_s - (typeof p.edge_ns === 'number' ? p.edge_ns * 1e-9 : 25e-9), p.end_s]);
    function lower(x) { let lo = 0, hi = n; while (lo < hi) { const m = (lo + hi) >> 1; if (t[m] < x) lo = m + 1; else hi = m; } return lo; }
    function isBad(x) { for (const b of bad) if (x >= b[0] && x <= b[1]) return true; return false; }
    let built = null;  // [t0, t1, step] of the data now in the plot
    // The samples of [x0, x1] for a view `w` wide: every sample when the view holds at most
    // 2 x kBuckets of them, else the min and max of each of kBuckets buckets per view width.
    function rows(x0, x1, w) {
      const i0 = Math.max(0, lower(x0) - 1), i1 = Math.min(n, lower(x1) + 1);
      const nb = Math.max(1, Math.ceil(kBuckets * (x1 - x0) / w));
      const out = [];
      const push = bad.length ? i => out.push([t[i], v[i], isBad(t[i]) ? v[i] : null]) : i => out.push([t[i], v[i]]);
      if (i1 - i0 <= 2 * nb) { for (let i = i0; i < i1; ++i) push(i); return out; }
      for (let b = 0; b < nb; ++b) {
        const a = i0 + Math.floor((i1 - i0) * b / nb), z = i0 + Math.floor((i1 - i0) * (b + 1) / nb);
        let lo = a, hi = a;
        for (let i = a; i < z; ++i) { if (v[i] < v[lo]) lo = i; if (v[i] > v[hi]) hi = i; }
        push(Math.min(lo, hi)); if (hi !== lo) push(Math.max(lo, hi));
      }
      return out;
    }
    let vmax = 0; for (let i = 0; i < n; ++i) if (isFinite(v[i])) vmax = Math.max(vmax, Math.abs(v[i]));
    const yr = Math.max(0.5, Math.ceil(vmax * 1.15 * 2) / 2);
    const full = [t[0], t[n - 1]];
    const div = el('div', {cls: 'plot wave'});
    const legend = el('div', {cls: 'legend'});
    host.append(div, legend);
    const done = waitFor();
    let g = null, rebuilding = false;
    function rebuild(range) {
      const w = range[1] - range[0];
      const x0 = Math.max(full[0], range[0] - w), x1 = Math.min(full[1], range[1] + w);
      built = [x0, x1, w];
      rebuilding = true;
      g.updateOptions({file: rows(x0, x1, w), dateWindow: range});
      rebuilding = false;
    }
    function underlay(ctx, area, gr) {
      const xr = gr.xAxisRange();
      ctx.save();
      ctx.font = '12px sans-serif';
      let lastRight = -1e9;
      frames.forEach((f, i) => {
        const last = pulses[f.last_pulse];
        const end = last ? last.end_s : f.start_s;
        if (end < xr[0] || f.start_s > xr[1]) return;
        const a = Math.max(area.x, gr.toDomXCoord(f.start_s)), b = Math.min(area.x + area.w, gr.toDomXCoord(end));
        ctx.fillStyle = f.fault && f.fault !== 'truncated' ? 'rgba(240,120,120,0.25)' : f.byte ? 'rgba(90,140,210,0.16)' : 'rgba(150,150,150,0.18)';
        ctx.fillRect(a, area.y, Math.max(1, b - a), area.h);
        const label = 'F' + i + ' ' + (f.byte ? '0x' + f.byte : f.fault || '?');
        const w = ctx.measureText(label).width;
        const x = Math.max(a + 3, area.x + 3);
        if (x > lastRight + 6 && x + w < area.x + area.w) {
          ctx.fillStyle = f.fault && f.fault !== 'truncated' ? '#9b1c1c' : '#33485f';
          ctx.fillText(label, x, area.y + 14);
          lastRight = x + w;
        }
      });
      ctx.strokeStyle = '#d4008f'; ctx.lineWidth = 1.5; ctx.setLineDash([6, 4]);
      for (const s of [1, -1]) {
        const y = gr.toDomYCoord(s * vth);
        ctx.beginPath(); ctx.moveTo(area.x, y); ctx.lineTo(area.x + area.w, y); ctx.stroke();
      }
      ctx.setLineDash([]);
      ctx.fillStyle = '#e00000';
      lastRight = -1e9;
      for (const p of failing) {
        const xm = gr.toDomXCoord((p.start_s + p.end_s) / 2);
        if (xm < area.x || xm > area.x + area.w) continue;
        ctx.beginPath(); ctx.moveTo(xm - 5, area.y + 18); ctx.lineTo(xm + 5, area.y + 18); ctx.lineTo(xm, area.y + 27); ctx.fill();
        const label = '#' + p.index;
        const w = ctx.measureText(label).width;
        if (xm - w / 2 > lastRight + 4) { ctx.fillText(label, xm - w / 2, area.y + 40); lastRight = xm + w / 2; }
      }
      ctx.restore();
    }
    g = new Dygraph(div, rows(full[0], full[1], full[1] - full[0]), {
      labels: ['time', 'v(P) - v(N)'].concat(bad.length ? ['failing pulse'] : []),
      colors: ['#1f3f77', '#e00000'],
      series: {'failing pulse': {strokeWidth: 2.5}},
      strokeWidth: 1.2,
      connectSeparatedPoints: false,
      valueRange: [-yr, yr],
      dateWindow: full,
      labelsDiv: legend,
      legend: 'always',
      xlabel: 'time', ylabel: 'V',
      axes: {x: {valueFormatter: x => si(x, 's'), axisLabelFormatter: x => si(x, 's')},
             y: {valueFormatter: y => fmt(y, 4) + ' V'}},
      underlayCallback: underlay,
      // Double-click: the whole record (dygraph's own reset would show only the data built).
      interactionModel: Object.assign({}, Dygraph.defaultInteractionModel, {dblclick: () => rebuild(full)}),
      drawCallback: function (gr, initial) {
        if (initial) { built = [full[0], full[1], full[1] - full[0]]; done(); return; }
        if (rebuilding) return;
        const r = gr.xAxisRange(), w = r[1] - r[0];
        // Rebuild when the view leaves the data built or the zoom changed by 1.5x or more.
        if (r[0] < built[0] - 1e-15 || r[1] > built[1] + 1e-15 || w < built[2] / 1.5 || w > built[2] * 1.5)
          setTimeout(() => rebuild(gr.xAxisRange()), 0);
      },
    });
    plots.push({kind: 'wave', graph: g, time: t});
    // Wheel: zoom around the cursor.
    div.addEventListener('wheel', e => {
      if (!e.ctrlKey && !e.altKey) return;  // a plain wheel scrolls the page
      e.preventDefault();
      const r = g.xAxisRange(), x = g.toDataXCoord(e.offsetX);
      const k = e.deltaY > 0 ? 1.25 : 0.8;
      const a = Math.max(full[0], x - (x - r[0]) * k), b = Math.min(full[1], x + (r[1] - x) * k);
      rebuild([a, b]);
    }, {passive: false});
    return {
      show: (a, b) => rebuild([Math.max(full[0], a), Math.min(full[1], b)]),
      reset: () => rebuild(full),
      pan: f => { const r = g.xAxisRange(), w = r[1] - r[0];
        let a = r[0] + f * w; a = Math.max(full[0], Math.min(full[1] - w, a)); rebuild([a, a + w]); },
      pulses: pulses, frames: frames, failing: failing,
    };
  }

  function waveControls(p) {
    const bar = el('div', {cls: 'controls'});
    bar.append(el('button', {type: 'button', text: 'whole record', onclick: () => p.reset()}),
               el('button', {type: 'button', text: '\u25c0 pan', onclick: () => p.pan(-0.5)}),
               el('button', {type: 'button', text: 'pan \u25b6', onclick: () => p.pan(0.5)}));
    if (p.frames.length) {
      const s = el('select', {'aria-label': 'zoom to a frame'}, [el('option', {value: '', text: 'zoom to frame...'})]);
      p.frames.forEach((f, i) => s.append(el('option', {value: i, text: 'F' + i + ' ' +
        (f.byte ? '0x' + f.byte : f.fault || '?') + ' at ' + si(f.start_s, 's')})));
      s.addEventListener('change', () => {
        if (s.value === '') return;
        const f = p.frames[+s.value], last = p.pulses[f.last_pulse];
        // A frame past report.json's first kMaxJsonPulses pulses has no end listed: one byte frame
        // (13 bit times of 500 ns, 6.5 us) and a little more.
        const end = last ? last.end_s : f.start_s + 7e-6, pad = (end - f.start_s) * 0.08;
        p.show(f.start_s - pad, end + pad);
      });
      bar.append(s);
    }
    if (p.failing.length) {
      const s = el('select', {'aria-label': 'zoom to a failing pulse'}, [el('option', {value: '', text: 'failing pulse...'})]);
      p.failing.slice(0, 500).forEach((q, i) => s.append(el('option', {value: i, text: '#' + q.index +
        ' (' + q.fails.join(', ') + ') at ' + si(q.start_s, 's')})));
      s.addEventListener('change', () => {
        if (s.value === '') return;
        const q = p.failing[+s.value];
        p.show(q.start_s - 1e-6, q.end_s + 1e-6);
      });
      bar.append(s);
    }
    bar.append(el('span', {cls: 'hint', text: 'drag to zoom, shift-drag to pan, ctrl-wheel to zoom, double-click for the whole record'}));
    return bar;
  }

  // --- a run ---
  function runPage() {
    const r = data.report, x = data.extra || {};
    const head = el('header', {}, [el('h1', {}, ['isolink report: ' + r.name + ' ', verdictBadge(r.verdict, 'verdict')])]);
    const wc = r.worst_case;
    head.append(el('p', {cls: 'sub', text: 'spec ' + (r.spec && r.spec.source || '') + ', simulated in ' + fmt(r.run_time_s, 3) + ' s' +
      (wc && wc.computed !== false ? '; worst case over all traffic: ' + (wc.verdict || '-').toUpperCase() : '')}));
    if (wc && wc.computed === false) head.append(el('p', {cls: 'note', text: 'No worst case over all traffic: ' + wc.why + '.'}));
    app.append(head);
    const why = section('Verdict', 'reasons');
    const dirRows = r.directions.map(d => {
      const c = d.check || d.tones || {};
      const w = (c.summary && c.summary.worst) || {};
      const cell = m => w[m] ? fmt(w[m].value, 4) + ' ' + w[m].unit + ' (' + signed(w[m].margin, 3) + ')' : '-';
      return {cells: [d.direction + ': ' + d.transmitter + ' -> ' + d.receiver, d.rules, verdictBadge(d.verdict),
        cell('vstart'), cell('vend'), cell('width'), cell('edge'),
        c.decoded ? clipText(c.decoded.bytes, 160, 'report.json, decoded.bytes') || '-' : '-']};
    });
    why.append(table(['direction', 'rules', 'verdict', 'worst VSTART', 'worst VEND', 'worst width', 'slowest edge', 'bytes decoded'], dirRows));
    for (const d of r.directions) {
      const reasons = [].concat((d.check && d.check.reasons) || [], (d.tones && d.tones.reasons) || []);
      if (!reasons.length) continue;
      why.append(el('p', {text: 'Why ' + d.direction + ' fails:'}),
        el('ul', {cls: 'reasons'}, reasons.slice(0, 20).map(t => el('li', {text: t}))));
    }
    if (wc && wc.verdict === 'fail')
      for (const d of wc.directions || []) if (d.reasons && d.reasons.length)
        why.append(el('p', {text: 'Worst case, ' + d.direction + ':'}), el('ul', {cls: 'reasons'}, d.reasons.slice(0, 10).map(t => el('li', {text: t}))));

    const waves = section('Received waveforms', 'waves');
    (data.waves || []).forEach((w0, i) => {
      const d = r.directions[i] || {};
      // Both directions of a symmetric link: the samples are embedded once.
      const w = w0.same_as != null ? Object.assign({}, data.waves[w0.same_as], {direction: w0.direction}) : w0;
      const box = el('div', {cls: 'wavebox'});
      box.append(el('h3', {}, [w.direction + ' ', verdictBadge(d.verdict)]));
      if (w.kept < w.samples)
        box.append(el('p', {cls: 'note', text: 'The record has ' + w.samples + ' samples; the page keeps ' + w.kept +
          (w.tolerance ? ', those that linear interpolation needs to stay within ' + fmt(w.tolerance * 1e3, 3) + ' mV of every sample,'
                       : ' (the lowest and highest of each bucket)') +
          ' to stay small. isolink run --wave rows writes every sample to wave.csv.'}));
      waves.append(box);
      const rules = d.check || d.tones;
      const p = wavePlot(box, w, rules, (x.vth || [])[i] || 1.2);
      box.insertBefore(waveControls(p), box.children[1]);
    });
    if (data.eye) {
      const s = section('Eye diagram', 'eye');
      s.append(image(data.eye, 'eye diagram'));
    }
    if (wc && wc.computed !== false) worstSection(wc);
    const bom = section('Bill of materials and cable', 'bom');
    bom.append(table(['end', 'as simulated'], [{cells: ['tx', x.bom && x.bom.tx]}, {cells: ['rx', x.bom && x.bom.rx]}]));
    if (x.cable) bom.append(el('p', {text: 'Cable: ' + x.cable}));
    if (r.spec && r.spec.stimulus)
      bom.append(el('p', {}, ['Traffic: ', el('code', {text: clipText(x.traffic || '', 400, 'the spec and report.md')})]));
    solverSection(r.directions);
  }

  function worstSection(wc) {
    const s = section('Worst case over all traffic', 'worst');
    s.append(el('p', {}, ['Verdict: ', verdictBadge(wc.verdict, 'worst-verdict')]));
    const names = {vstart: 'lowest VSTART', vend: 'lowest VEND', width_min: 'narrowest pulse', width_max: 'widest pulse', edge: 'slowest edge'};
    for (const d of wc.directions || []) {
      s.append(el('h3', {}, [d.direction + ' ', verdictBadge(d.verdict)]));
      const rows = [];
      for (const m in d.worst || {}) {
        const w = d.worst[m];
        const block = w.reproduce ? w.reproduce.stimulus : '';
        const pre = el('pre', {cls: 'replay', text: block});
        rows.push({attrs: {'data-metric': m}, cells: [names[m] || m, fmt(w.value, 4) + ' ' + w.unit, fmt(w.limit, 4) + ' ' + w.unit,
          el('span', {cls: w.margin < 0 ? 'neg' : 'pos', text: signed(w.margin, 3) + ' ' + w.unit}),
          (w.frames || []).join(' ') + ' (gaps ' + (w.gaps_us || []).map(g => fmt(g, 3)).join(', ') + ' us)',
          w.pulse ? w.pulse.sign + ' ' + w.pulse.role + ' at ' + fmt(w.pulse.time_us, 4) + ' us' : '-',
          el('div', {cls: 'replaybox'}, [pre, copyButton(block)])]});
      }
      s.append(table(['metric', 'worst', 'limit', 'margin', 'traffic (bytes; gap before each)', 'pulse', 'reproduce (stimulus block for isolink run)'], rows, {cls: 'worst'}));
    }
  }

  function solverSection(dirs) {
    const s = section('Solver', 'solver');
    const keys = [];
    for (const d of dirs) for (const k in d.solver || {}) if (!keys.includes(k) && typeof d.solver[k] !== 'object') keys.push(k);
    s.append(table(['', ...dirs.map(d => d.direction)], keys.map(k => ({cells: [k.replace(/_/g, ' '),
      ...dirs.map(d => { const v = d.solver[k]; return typeof v === 'number' ? fmt(v, 5) : v; })]}))));
    for (const d of dirs) {
      const m = d.solver && d.solver.reduced_model;
      if (m) s.append(el('p', {cls: 'note', text: d.direction + ': reduced model of order ' + m.order + ', ' + m.poles +
        ' poles, AC error ' + fmt(m.ac_error, 2) + ' of the peak (at ' + si(m.ac_error_hz, 'Hz') + ')'}));
      for (const w of (d.solver && d.solver.warnings) || []) s.append(el('p', {cls: 'note', text: w}));
    }
  }

  // --- a sweep ---
  function sweepPage() {
    const pts = data.points;
    const nfail = pts.filter(p => p.verdict !== 'pass').length;
    app.append(el('header', {}, [el('h1', {}, ['isolink sweep: ' + data.title + ' ',
      verdictBadge(nfail ? 'fail' : 'pass', 'verdict')]),
      el('p', {cls: 'sub', text: pts.length + ' points, ' + (pts.length - nfail) + ' pass, ' + nfail +
        ' fail or error; ' + data.source + (data.note ? '; ' + data.note : '')})]));
    const rowsById = {};
    const tsec = section('Results', 'results');
    const head = ['point', ...data.columns, 'verdict', 'worst metric', 'worst margin', 'why'];
    const t = table(head, pts.map(p => ({attrs: {id: 'point-' + p.index},
      cells: [p.index, ...p.cells, verdictBadge(p.verdict), p.worst_metric,
        p.margin == null ? '-' : signed(p.margin * 100, 3) + ' %', p.error || p.reason || '']})), {cls: 'results'});
    for (const tr of t.tBodies[0].rows) rowsById[tr.id] = tr;
    function openRows(list) {
      for (const tr of t.querySelectorAll('tr.hl')) tr.classList.remove('hl');
      list.forEach((p, k) => { const tr = rowsById['point-' + p.index]; if (!tr) return;
        tr.classList.add('hl'); if (k === 0) tr.scrollIntoView({block: 'center', behavior: 'smooth'}); });
    }
    if (data.axes.length) {
      const s = section('Worst margin', 'margins');
      app.insertBefore(s, tsec);
      marginPlot(s, openRows);
    }
    tsec.append(el('div', {cls: 'scroll'}, [t]));
  }

  // One line per value of axis 1 (or one line), the worst margin of each cell in %.
  function marginPlot(host, openRows) {
    const ax = data.axes[0], ax1 = data.axes[1];
    const xs = ax.values.length ? ax.values : ax.labels.map((_, i) => i);
    const nser = ax1 ? ax1.labels.length : 1;
    const cells = {};  // "ix,is" -> points
    for (const p of data.points) {
      const key = p.axis[0] + ',' + (ax1 ? p.axis[1] : 0);
      (cells[key] = cells[key] || []).push(p);
    }
    function worst(list) {
      let m = null; for (const p of list) if (p.margin != null && (m == null || p.margin < m)) m = p.margin; return m;
    }
    const order = xs.map((x, i) => i).sort((a, b) => xs[a] - xs[b]);
    const rows = order.map(ix => [xs[ix], ...Array.from({length: nser}, (_, is) => {
      const l = cells[ix + ',' + is]; const m = l ? worst(l) : null; return m == null ? null : m * 100; })]);
    // A numeric axis names its values with their unit ("1.538 nF"), as an engineer reads them.
    const valueText = (a, i) => a.values.length ? si(a.values[i], a.unit) : a.labels[i];
    const labels = [ax.name, ...(ax1 ? ax1.labels.map((l, i) => ax1.name + ' = ' + valueText(ax1, i)) : ['worst margin'])];
    const div = el('div', {cls: 'plot margin'}), legend = el('div', {cls: 'legend'}), info = el('div', {cls: 'pointinfo', id: 'point-info', text: 'Hover a point for its values; click it to open its row.'});
    host.append(div, legend, info);
    const done = waitFor();
    const unit = ax.unit ? ' (' + ax.unit + ')' : '';
    function cellOf(row, col) { return cells[order[row] + ',' + (col - 1)] || []; }
    function describe(list) {
      return list.map(p => 'point ' + p.index + ': ' + data.columns.map((c, k) => c + ' = ' + p.cells[k]).join(', ') +
        '; ' + p.verdict.toUpperCase() + (p.margin == null ? '' : ', worst ' + p.worst_metric + ' ' + signed(p.margin * 100, 3) + ' %') +
        (p.reason ? ' (' + p.reason + ')' : '') + (p.error ? ' (' + p.error + ')' : '')).join('\n');
    }
    const g = new Dygraph(div, rows, {
      labels: labels, labelsDiv: legend, legend: 'always',
      drawPoints: true, pointSize: 4, highlightCircleSize: 7, strokeWidth: 2, xRangePad: 12,
      xlabel: ax.name + unit, ylabel: 'worst relative margin (%)',
      logscale: false, axes: {x: {logscale: !!ax.log && ax.values.length > 0,
        axisLabelFormatter: x => ax.values.length ? fmt(x, 3) : (ax.labels[Math.round(x)] || ''),
        valueFormatter: x => ax.values.length ? fmt(x, 4) + (ax.unit ? ' ' + ax.unit : '') : (ax.labels[Math.round(x)] || '')},
        y: {valueFormatter: y => signed(y, 3) + ' %'}},
      underlayCallback: (ctx, area, gr) => {
        const y0 = gr.toDomYCoord(0);
        ctx.fillStyle = 'rgba(60,160,70,0.08)';
        ctx.fillRect(area.x, area.y, area.w, Math.max(0, Math.min(area.h, y0 - area.y)));
        ctx.strokeStyle = '#d4008f'; ctx.lineWidth = 1.5;
        ctx.beginPath(); ctx.moveTo(area.x, y0); ctx.lineTo(area.x + area.w, y0); ctx.stroke();
      },
      drawPointCallback: (gr, name, ctx, cx, cy, color, size, row) => {
        const col = gr.getLabels().indexOf(name);
        const list = cellOf(row, col);
        const fail = list.some(p => p.verdict !== 'pass');
        ctx.beginPath(); ctx.fillStyle = fail ? '#e00000' : color;
        if (fail) { ctx.rect(cx - size, cy - size, 2 * size, 2 * size); } else { ctx.arc(cx, cy, size, 0, 2 * Math.PI); }
        ctx.fill();
      },
      highlightCallback: (e, x, pts, row, name) => {
        const col = g.getLabels().indexOf(name);
        info.textContent = describe(cellOf(row, col));
      },
      highlightSeriesOpts: {strokeWidth: 3},
      clickCallback: () => { const sel = g.getSelection(); if (sel < 0) return;
        const name = g.getHighlightSeries(); openRows(cellOf(sel, g.getLabels().indexOf(name))); },
      drawCallback: (gr, initial) => { if (initial) done(); },
    });
    plots.push({kind: 'margin', graph: g});
    host.append(el('p', {cls: 'note', text: 'Squares: points that fail (or a cell where any point fails). The shaded side of 0 % passes.'}));
  }

  // --- a pack ---
  function packPage() {
    const r = data.report;
    app.append(el('header', {}, [el('h1', {}, ['isolink pack: ' + r.name + ' ', verdictBadge(r.verdict, 'verdict')]),
      el('p', {cls: 'sub', text: r.bridge + ' bridge, ' + r.devices + ' x ' + r.stack + (r.ring ? ', ring' : '') +
        '; weakest hop ' + (r.weakest_hop || '-') + '; worst case over all traffic: ' + String(r.worst_verdict).toUpperCase() +
        '; ' + r.simulations + ' circuits simulated in ' + fmt(r.run_time_s, 3) + ' s'})]));
    if (data.diagram) section('Chain', 'diagram').append(image(data.diagram, 'pack diagram'));
    const s = section('Hops', 'hops');
    s.append(table(['hop', 'from', 'to', 'verdict', 'worst margin', 'metric', 'worst case', 'worst-case margin', 'cable delay', 'link'],
      r.hops.map(h => ({attrs: {cls: h.index === r.weakest_hop ? 'weakest' : ''}, cells: [h.index, h.from, h.to, verdictBadge(h.verdict),
        h.worst_margin_rel == null ? '-' : signed(h.worst_margin_rel * 100, 3) + ' %', h.worst_metric + (h.worst_direction ? ' (' + h.worst_direction + ')' : ''),
        verdictBadge(h.worst_case_verdict), h.worst_case_margin_rel == null ? '-' : signed(h.worst_case_margin_rel * 100, 3) + ' %',
        si(h.cable_delay_s, 's'), h.link ? h.link.cable.length + ' m ' + h.link.tx.isolation.type + ' / ' + h.link.rx.isolation.type : '']}))));
    if (r.ring_breaks && r.ring_breaks.length) {
      const b = section('Ring: one cable broken', 'breaks');
      b.append(table(['broken hop', 'normal side', 'reverse side', 'unreached', 'verdict', 'failing', 'worst case'],
        r.ring_breaks.map(x => ({cells: [x.broken_hop, x.normal_side, x.reverse_side, x.unreached, verdictBadge(x.verdict),
          (x.failing || []).join(' '), verdictBadge(x.worst_verdict)]}))));
    }
    const tm = r.timing;
    if (tm && tm.commands && tm.commands.length) {
      const c = section('Command timing', 'timing');
      c.append(table(['command', 'route', 'last arrival', 'response done', 'late', 'note'],
        tm.commands.map(x => ({cells: [x.command, x.route, si(Math.max(...x.arrival_s.filter(a => a != null)), 's'),
          si(x.response_done_s, 's'), x.late ? 'LATE' : 'no', x.note]}))));
    }
  }

  // --- a stress run ---
  const kPinColors = {txp: '#1f77b4', txn: '#ff7f0e', rxp: '#2ca02c', rxn: '#9467bd'};
  // A scenario's pin voltages (each to its own device ground) with the pin limit dashed and the
  // disturbance shaded.
  function pinPlot(host, sc, pins, limit) {
    const t = decode(pins.t, Float64Array);
    const names = Object.keys(pins.pins);
    const cols = names.map(k => decode(pins.pins[k], Float32Array));
    const rows = [];
    for (let i = 0; i < t.length; ++i) rows.push([t[i]].concat(cols.map(c => c[i])));
    const div = el('div', {cls: 'plot wave'});
    host.append(div);
    const done = waitFor();
    const g = new Dygraph(div, rows, {
      labels: ['time'].concat(names.map(k => k + ' to ' + (sc.pin_ground[k] || '?'))),
      colors: names.map(k => kPinColors[k] || '#7f7f7f'),
      xlabel: 'time', ylabel: 'pin to its ground [V]', legend: 'always', labelsSeparateLines: false,
      axes: {x: {axisLabelFormatter: x => si(x, 's'), valueFormatter: x => si(x, 's')}},
      valueRange: [Math.min(-limit, ...names.map(k => sc.peak_pin_v[k].min)) * 1.1,
                   Math.max(limit, ...names.map(k => sc.peak_pin_v[k].max)) * 1.1],
      underlayCallback: (ctx, area, gr) => {
        const win = sc.window_s;
        if (win) {
          const a = Math.max(area.x, gr.toDomXCoord(win[0])), b = Math.min(area.x + area.w, gr.toDomXCoord(win[1]));
          ctx.fillStyle = 'rgba(242,142,0,0.15)'; ctx.fillRect(a, area.y, Math.max(1, b - a), area.h);
        }
        ctx.strokeStyle = '#e00000'; ctx.lineWidth = 1.5; ctx.setLineDash([8, 5]);
        for (const s of [1, -1]) { const y = gr.toDomYCoord(s * limit);
          ctx.beginPath(); ctx.moveTo(area.x, y); ctx.lineTo(area.x + area.w, y); ctx.stroke(); }
        ctx.setLineDash([]);
      },
      drawCallback: (gr, initial) => { if (initial) done(); },
    });
    plots.push({kind: 'pins', graph: g, id: sc.id});
    if (pins.kept < pins.samples)
      host.append(el('p', {cls: 'note', text: 'Drawn from ' + pins.kept + ' of ' + pins.samples +
        ' samples: each pin\'s lowest and highest per bucket, so every peak is on the plot.'}));
  }
  function stressPage() {
    const r = data.report;
    const ok = r.survives && r.communicates;
    app.append(el('header', {}, [el('h1', {}, ['isolink stress: ' + r.spec + ' ', verdictBadge(ok ? 'pass' : 'fail', 'verdict')]),
      el('p', {cls: 'sub', text: r.verdict + ' (' + r.scenarios.length + ' scenarios in ' + fmt(r.seconds, 3) + ' s)'})]));
    const lim = section('Limits', 'limits');
    lim.append(table(['limit', 'value', 'source'], Object.keys(r.limits).map(k => ({cells: [k, fmt(r.limits[k].value, 4), r.limits[k].source]}))));
    if (data.image) section('Pins over time', 'figure').append(image(data.image, 'stress.png'));
    const pinLimit = r.limits.pin_abs_max_V ? r.limits.pin_abs_max_V.value : 20;
    const sc = section('Scenarios', 'scenarios');
    function peaks(s) { return Object.keys(s.peak_pin_v).map(k => k + ' ' + fmt(s.peak_pin_v[k].min, 3) + '..' + fmt(s.peak_pin_v[k].max, 3)).join(', '); }
    function level(s) { return Object.keys(s.level).map(k => k + ' ' + fmt(s.level[k], 4)).join(', '); }
    function yesNo(x) { return x == null ? '-' : x ? 'yes' : 'NO'; }
    sc.append(table(['scenario', 'kind', 'level', 'pins: min..max [V]', 'peak CM [V]', 'survives', 'communicates', 'first broken'],
      r.scenarios.map(s => ({attrs: {cls: s.first_broken ? 'broken' : ''}, cells: [el('a', {href: '#sc-' + s.id, text: s.id}), s.kind, level(s), peaks(s),
        fmt(s.peak_cm_V, 3), yesNo(s.survives), yesNo(s.communicates), s.first_broken || '-']}))));
    for (const s of r.scenarios) {
      const d = section(s.id + (s.first_broken ? ': breaks' : ''), 'sc-' + s.id);
      d.append(el('p', {text: s.description}));
      if (s.first_broken) d.append(el('p', {cls: 'error', text: (s.broken || [s.first_broken]).join('; ')}));
      if (data.pins && data.pins[s.id]) pinPlot(d, s, data.pins[s.id], pinLimit);
      if (s.diodes && s.diodes.length)
        d.append(table(['part', 'probe', 'peak current', 'energy', 'rating'], s.diodes.map(x => ({cells: [x.what, x.probe, si(x.peak_A, 'A'),
          x.energy_J == null ? '-' : si(x.energy_J, 'J'), x.rating_A ? si(x.rating_A.value, 'A') : '-']}))));
      if (s.traffic) { const t = s.traffic;
        d.append(el('p', {text: 'Traffic at ' + s.receiver.p + '/' + s.receiver.n + ' (' + s.receiver.rules + '): ' + t.bytes_decoded + ' of ' + t.bytes_sent +
          ' bytes decoded, ' + t.decoded_during + ' of ' + t.bytes_during + ' during the disturbance; recovery ' + (t.recovery_s == null ? 'not within the record' : si(t.recovery_s, 's')) +
          (t.first_failure ? '; first failure: ' + t.first_failure : '')})); }
      if (s.netlist) d.append(el('p', {cls: 'note', text: 'netlist: ' + s.netlist}));
    }
  }

  // The page itself counts as one pending plot until it is built; an error leaves data-ready 0.
  const built = waitFor();
  try {
    if (kind === 'run') runPage(); else if (kind === 'sweep') sweepPage(); else if (kind === 'pack') packPage(); else if (kind === 'stress') stressPage();
    built();
  } catch (e) {
    app.prepend(el('p', {cls: 'error', text: 'report.html could not draw: ' + e}));
    throw e;
  }
})();
