// pvtc's interactive view of PVT motion. Written for pvtc, no third-party code; it
// requests nothing over a network. The data block (#pvtc-data) is zlib-deflated,
// base64: a little-endian u32 length, the metadata as JSON, then each motion's spans
// and the programmed path as zigzag varints (crates/pvt-emit/src/view/encode.rs).
'use strict';
(function () {
  const view = (window.pvtcView = {});
  const COLORS = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#8c564b', '#e377c2'];
  const QUANTITIES = ['position', 'velocity', 'acceleration', 'jerk'];
  const SYMBOLS = ['p', 'v', 'a', 'j'];
  let BLOCK = 64;

  // ---------------------------------------------------------------- data
  function fromBase64(text) {
    if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text.trim());
    const table = new Uint8Array(128);
    const alphabet = 'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/';
    for (let i = 0; i < 64; i++) table[alphabet.charCodeAt(i)] = i;
    let n = text.length;
    while (n > 0 && (text.charCodeAt(n - 1) === 61 || text.charCodeAt(n - 1) <= 32)) n--;
    let start = 0;
    while (start < n && text.charCodeAt(start) <= 32) start++;
    const len = n - start;
    const out = new Uint8Array(Math.floor((len * 3) / 4));
    let o = 0, acc = 0, bits = 0;
    for (let i = start; i < n; i++) {
      acc = (acc << 6) | table[text.charCodeAt(i)];
      bits += 6;
      if (bits >= 8) {
        bits -= 8;
        out[o++] = (acc >> bits) & 255;
      }
    }
    return out.subarray(0, o);
  }

  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // Zigzag varints from a byte array.
  class Reader {
    constructor(bytes, pos) {
      this.b = bytes;
      this.p = pos;
    }

    zig() {
      const b = this.b;
      let byte = b[this.p++];
      if (byte < 128) return byte & 1 ? -(byte + 1) / 2 : byte / 2;
      let n = byte & 127, scale = 128;
      do {
        byte = b[this.p++];
        n += (byte & 127) * scale;
        scale *= 128;
      } while (byte & 128);
      return n % 2 === 0 ? n / 2 : -(n + 1) / 2;
    }
  }

  // One motion: spans (pieces and dwells), knots' positions and velocities per axis.
  function decodeMotion(bytes, pos, m, dim, q) {
    const n = m.spans;
    const r = new Reader(bytes, pos);
    const start = new Float64Array(n + 1);
    const line = new Uint32Array(n);
    const kind = new Uint8Array(n);
    const P = new Float64Array((n + 1) * dim);
    const V = new Float64Array((n + 1) * dim);
    // Typed state: the loop runs over every span and axis.
    const p0 = Float64Array.from(m.start), v0 = new Float64Array(dim), vb = new Float64Array(dim);
    const qp = Float64Array.from(q.position), qv = Float64Array.from(q.velocity);
    const ratio = qv.map((v, k) => v / qp[k]), TQ = q.time;
    for (let k = 0; k < dim; k++) P[k] = p0[k] * qp[k];
    let d = 0, ln = 0, t = 0;
    for (let i = 0; i < n; i++) {
      d += r.zig();
      const lk = r.zig();
      const kd = ((lk % 4) + 4) % 4;
      ln += (lk - kd) / 4;
      kind[i] = kd;
      line[i] = ln;
      t += d * TQ;
      start[i + 1] = t;
      const o = (i + 1) * dim;
      for (let k = 0; k < dim; k++) {
        const v1 = 2 * v0[k] - vb[k] + r.zig();
        const mean = Math.floor(d * TQ * (v0[k] + v1) * ratio[k] / 2 + 0.5);
        const p1 = p0[k] + mean + r.zig();
        vb[k] = v0[k];
        v0[k] = v1;
        p0[k] = p1;
        P[o + k] = p1 * qp[k];
        V[o + k] = v1 * qv[k];
      }
    }
    // The exact start acceleration and jerk where those from the grid values are off,
    // by span and axis (in order).
    const fixes = r.zig();
    const fixed = new Uint8Array(fixes ? n : 0), fixKeys = new Int32Array(fixes), fixValues = new Float64Array(2 * fixes);
    const bits = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    for (let f = 0, i = 0; f < fixes; f++) {
      i += r.zig();
      const k = r.zig();
      fixKeys[f] = i * dim + k;
      fixValues[2 * f] = bits.getFloat64(r.p, true);
      fixValues[2 * f + 1] = bits.getFloat64(r.p + 8, true);
      r.p += 16;
      fixed[i] = 1;
    }
    const blocksAt = r.p;
    const empty = { lines: new Int32Array(0), text: '', starts: new Int32Array(1) };
    const motion = { name: m.name, n, dim, start, line, kind, P, V, pt: m.pt, texts: empty, total: t, fixed, fixKeys, fixValues };
    motion.pieces = 0;
    for (let i = 0; i < n; i++) if (kind[i] !== 2) motion.pieces++;
    buildBlocks(motion, bytes, blocksAt);
    return motion;
  }

  // The lines the pieces name and their text: the lines as varints of their
  // differences, then the texts, each ended by a line feed.
  function decodeTexts(bytes, pos, t) {
    const r = new Reader(bytes, pos);
    const lines = new Int32Array(t.lines);
    for (let i = 0, l = 0; i < t.lines; i++) lines[i] = l += r.zig();
    const text = new TextDecoder().decode(bytes.subarray(pos + t.lineBytes, pos + t.lineBytes + t.textBytes));
    const starts = new Int32Array(t.lines + 1);
    for (let i = 0, at = 0; i < t.lines; i++) {
      starts[i] = at;
      at = text.indexOf('\n', at) + 1;
      starts[i + 1] = at;
    }
    return { lines, text, starts, bytes: t.lineBytes + t.textBytes };
  }

  // The lines' text of every motion and the programmed path, from their own block.
  async function readLater(state) {
    const { meta, motions, dim } = state;
    const block = document.getElementById('pvtc-later');
    const raw = await inflate(fromBase64(block.textContent));
    block.textContent = '';
    let pos = 0;
    meta.motions.forEach((m, i) => {
      motions[i].texts = decodeTexts(raw, pos, m.texts);
      pos += m.texts.lineBytes + m.texts.textBytes;
    });
    if (meta.programmed) {
      state.programmed = decodeProgrammed(raw, pos, meta.programmed, dim, meta.quanta);
      state.addProgrammed();
      state.draw3d();
    }
    state.timings.later = performance.now();
    return true;
  }

  // The text of a line, if the page holds it.
  function textOf(M, line) {
    const L = M.texts.lines;
    let a = 0, b = L.length - 1;
    while (a <= b) {
      const mid = (a + b) >> 1;
      if (L[mid] === line) return M.texts.text.slice(M.texts.starts[mid], M.texts.starts[mid + 1] - 1);
      if (L[mid] < line) a = mid + 1; else b = mid - 1;
    }
    return undefined;
  }

  // The cubic of span i, axis k: [p0, v0, a0, j] in the span's own time.
  function coeffs(M, i, k, out) {
    const dim = M.dim, T = M.start[i + 1] - M.start[i];
    const p0 = M.P[i * dim + k], p1 = M.P[(i + 1) * dim + k];
    if (M.kind[i] === 2 || T <= 0) {
      out[0] = p1; out[1] = 0; out[2] = 0; out[3] = 0;
      return T;
    }
    if (M.pt) {
      out[0] = p0; out[1] = M.V[(i + 1) * dim + k]; out[2] = 0; out[3] = 0;
      return T;
    }
    const v0 = M.V[i * dim + k], v1 = M.V[(i + 1) * dim + k], D = p1 - p0;
    out[0] = p0;
    out[1] = v0;
    // The same operations as encode.rs' page_cubic.
    out[2] = (6 * D) / (T * T) - (4 * v0 + 2 * v1) / T;
    out[3] = (6 * (v0 + v1)) / (T * T) - (12 * D) / (T * T * T);
    if (M.fixed.length && M.fixed[i]) {
      const key = i * dim + k, keys = M.fixKeys;
      let a = 0, b = keys.length - 1;
      while (a <= b) {
        const mid = (a + b) >> 1;
        if (keys[mid] === key) { out[2] = M.fixValues[2 * mid]; out[3] = M.fixValues[2 * mid + 1]; break; }
        if (keys[mid] < key) a = mid + 1; else b = mid - 1;
      }
    }
    return T;
  }

  function valueAt(c, q, s) {
    switch (q) {
      case 0: return c[0] + s * (c[1] + s * (c[2] / 2 + (s * c[3]) / 6));
      case 1: return c[1] + s * (c[2] + (s * c[3]) / 2);
      case 2: return c[2] + s * c[3];
      default: return c[3];
    }
  }

  // Min and max of quantity q of the cubic c over [s0, s1], into out.
  function extent(c, q, s0, s1, out) {
    let lo = valueAt(c, q, s0), hi = lo;
    const b = valueAt(c, q, s1);
    if (b < lo) lo = b;
    if (b > hi) hi = b;
    let r1 = NaN, r2 = NaN;
    if (q === 0) {
      // Where the velocity v0 + a0 s + j s²/2 is zero.
      const A = c[3] / 2, B = c[2], C = c[1];
      if (A === 0) {
        if (B !== 0) r1 = -C / B;
      } else {
        const disc = B * B - 4 * A * C;
        if (disc >= 0) {
          const root = Math.sqrt(disc);
          r1 = (-B - root) / (2 * A);
          r2 = (-B + root) / (2 * A);
        }
      }
    } else if (q === 1 && c[3] !== 0) {
      r1 = -c[2] / c[3];
    }
    if (r1 > s0 && r1 < s1) {
      const x = valueAt(c, q, r1);
      if (x < lo) lo = x;
      if (x > hi) hi = x;
    }
    if (r2 > s0 && r2 < s1) {
      const x = valueAt(c, q, r2);
      if (x < lo) lo = x;
      if (x > hi) hi = x;
    }
    out[0] = lo;
    out[1] = hi;
  }

  // Per block of BLOCK spans, per axis and quantity, the min and max (written by the
  // encoder from the exact motion, as floats rounded outwards): a segment tree.
  function buildBlocks(M, bytes, pos) {
    const blocks = Math.ceil(M.n / BLOCK) || 1;
    let size = 1;
    while (size < blocks) size *= 2;
    M.treeSize = size;
    M.trees = [[], [], [], []];
    const bits = new DataView(bytes.buffer, bytes.byteOffset + pos, M.dim * 4 * blocks * 8);
    let at = 0;
    for (let k = 0; k < M.dim; k++) {
      for (let q = 0; q < 4; q++) {
        const lo = new Float64Array(2 * size).fill(Infinity), hi = new Float64Array(2 * size).fill(-Infinity);
        for (let b = 0; b < blocks && M.n; b++, at += 8) {
          lo[size + b] = bits.getFloat32(at, true);
          hi[size + b] = bits.getFloat32(at + 4, true);
        }
        for (let b = size - 1; b >= 1; b--) {
          lo[b] = Math.min(lo[2 * b], lo[2 * b + 1]);
          hi[b] = Math.max(hi[2 * b], hi[2 * b + 1]);
        }
        M.trees[q].push({ lo, hi });
      }
    }
    return at;
  }

  // The span running at t: the last starting at or before it (clamped).
  function spanAt(M, t) {
    let a = 0, b = M.n - 1;
    if (M.n === 0) return -1;
    if (t <= M.start[0]) return 0;
    while (a < b) {
      const mid = (a + b + 1) >> 1;
      if (M.start[mid] <= t) a = mid; else b = mid - 1;
    }
    return a;
  }

  const scratch = new Float64Array(4), ext = new Float64Array(2);
  // Min and max of quantity q on axis k of motion M over times [ta, tb]: exact, the
  // ends of partly covered spans by their cubic, whole blocks from the tree.
  function rangeOf(M, q, k, ta, tb, out) {
    let lo = Infinity, hi = -Infinity;
    const take = (l, h) => { if (l < lo) lo = l; if (h > hi) hi = h; };
    if (M.n === 0) { out[0] = 0; out[1] = 0; return; }
    if (ta < 0) {
      take(q === 0 ? M.P[k] : 0, q === 0 ? M.P[k] : 0);
    }
    if (tb > M.total) {
      const x = q === 0 ? M.P[M.n * M.dim + k] : 0;
      take(x, x);
    }
    const a = Math.max(ta, 0), b = Math.min(tb, M.total);
    if (a <= b) {
      const i0 = spanAt(M, a), i1 = spanAt(M, b);
      const part = (i, s0, s1) => {
        const T = coeffs(M, i, k, scratch);
        extent(scratch, q, Math.max(0, s0), Math.min(T, s1), ext);
        take(ext[0], ext[1]);
      };
      if (i0 === i1) {
        part(i0, a - M.start[i0], b - M.start[i0]);
      } else {
        part(i0, a - M.start[i0], Infinity);
        part(i1, 0, b - M.start[i1]);
        let i = i0 + 1;
        const tree = M.trees[q][k];
        while (i < i1 && i % BLOCK !== 0) part(i++, 0, Infinity);
        let b0 = i / BLOCK;
        const b1 = Math.floor(i1 / BLOCK);
        if (b1 > b0) {
          let l = b0 + M.treeSize, r = b1 + M.treeSize;
          while (l < r) {
            if (l & 1) { take(tree.lo[l], tree.hi[l]); l++; }
            if (r & 1) { r--; take(tree.lo[r], tree.hi[r]); }
            l >>= 1; r >>= 1;
          }
          i = b1 * BLOCK;
        }
        while (i < i1) part(i++, 0, Infinity);
      }
    }
    out[0] = lo;
    out[1] = hi;
  }

  function decodeProgrammed(bytes, pos, meta, dim, q) {
    const r = new Reader(bytes, pos);
    const last = new Array(dim).fill(0);
    const lines = [];
    const step = meta.step / meta.scale;
    for (let c = 0; c < meta.polylines; c++) {
      const count = r.zig(), rapid = r.zig() === 1;
      const pts = new Float64Array(count * dim);
      for (let i = 0; i < count; i++) {
        for (let k = 0; k < dim; k++) {
          last[k] += r.zig();
          pts[i * dim + k] = last[k] * step * meta.scale;
        }
      }
      lines.push({ pts, rapid });
    }
    return lines;
  }

  // ---------------------------------------------------------------- page
  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'class') e.className = v; else if (k.startsWith('on')) e.addEventListener(k.slice(2), v); else e.setAttribute(k, v);
    }
    for (const c of children) e.append(c);
    return e;
  }

  function fmt(x, digits) {
    if (!isFinite(x)) return String(x);
    const a = Math.abs(x);
    if (a !== 0 && (a >= 1e6 || a < 1e-3)) return x.toExponential(3);
    return x.toFixed(digits === undefined ? 4 : digits);
  }

  function speedColor(f) {
    // A perceptual ramp from dark blue through teal and green to yellow.
    const stops = [[48, 18, 59], [65, 69, 171], [57, 162, 252], [27, 229, 181], [116, 254, 93], [201, 239, 52], [251, 185, 56], [245, 105, 24], [201, 41, 4]];
    const x = Math.max(0, Math.min(1, f)) * (stops.length - 1);
    const i = Math.min(stops.length - 2, Math.floor(x)), u = x - i;
    const c = stops[i].map((s, j) => Math.round(s + (stops[i + 1][j] - s) * u));
    return `rgb(${c[0]},${c[1]},${c[2]})`;
  }

  async function main() {
    const timings = (view.timings = { start: performance.now() });
    const block = document.getElementById('pvtc-data');
    const packed = fromBase64(block.textContent);
    timings.base64 = performance.now();
    const raw = await inflate(packed);
    timings.inflated = performance.now();
    block.textContent = '';
    const metaLength = raw[0] | (raw[1] << 8) | (raw[2] << 16) | (raw[3] * 16777216);
    const meta = JSON.parse(new TextDecoder().decode(raw.subarray(4, 4 + metaLength)));
    const dim = meta.axes.length;
    BLOCK = meta.block;
    let pos = 4 + metaLength;
    const motions = meta.motions.map((m) => {
      const M = decodeMotion(raw, pos, m, dim, meta.quanta);
      pos += m.bytes;
      return M;
    });
    timings.decoded = performance.now();
    const state = {
      meta, dim, motions,
      total: Math.max(...motions.map((M) => M.total), 1e-9),
      programmed: [],
      window: null, cursor: null, pinned: null,
      rapids: 'faded', showProgrammed: true, shown: motions.map(() => true),
    };
    state.window = [0, state.total];
    buildPage(state);
    view.summary = () => summary(state);
    view.state = state;
    state.timings = timings;
    timings.page = performance.now();
    state.draw3dNow();
    timings.drawn3d = performance.now();
    state.drawPlotsNow();
    timings.drawnPlots = performance.now();
    view.readyMs = performance.now();
    // The lines' text and the programmed path, once the motion is drawn.
    view.texts = readLater(state);
    document.body.dataset.ready = '1';
    return view.summary();
  }

  function summary(state) {
    const out = { axes: state.meta.axes, units: state.meta.units, motions: [] };
    for (const M of state.motions) {
      const peaks = {};
      state.meta.axes.forEach((a, k) => {
        const each = {};
        QUANTITIES.forEach((name, q) => {
          rangeOf(M, q, k, 0, M.total, ext);
          each[name] = q === 0 ? [ext[0], ext[1]] : Math.max(Math.abs(ext[0]), Math.abs(ext[1]));
        });
        peaks[a] = each;
      });
      out.motions.push({ name: M.name, pieces: M.pieces, spans: M.n, totalTime: M.total, peaks });
    }
    out.findings = state.meta.findings.length;
    return out;
  }

  function buildPage(state) {
    const { meta, motions } = state;
    const header = el('header', {}, el('h1', {}, meta.title));
    motions.forEach((M, m) => {
      const box = el('input', { type: 'checkbox', checked: '' });
      box.addEventListener('change', () => { state.shown[m] = box.checked; redrawAll(state); });
      const label = m === 0 ? 'coloured by speed' : 'orange';
      header.append(el('label', { class: 'motion', title: label }, box, ` ${M.name}: ${M.pieces} pieces, ${fmt(M.total, 6)} s`));
    });
    const rapids = el('select', {}, el('option', { value: 'faded' }, 'rapids faded'), el('option', { value: 'shown' }, 'rapids shown'), el('option', { value: 'hidden' }, 'rapids hidden'));
    rapids.addEventListener('change', () => { state.rapids = rapids.value; state.draw3d(); });
    header.append(rapids);
    // The programmed path's switch, once it is read.
    state.addProgrammed = () => {
      const box = el('input', { type: 'checkbox', checked: '' });
      box.addEventListener('change', () => { state.showProgrammed = box.checked; state.draw3d(); });
      header.insertBefore(el('label', {}, box, ' programmed path'), reset);
    };
    const reset = el('button', { type: 'button' }, 'whole program');
    reset.addEventListener('click', () => { state.window = [0, state.total]; redrawAll(state); });
    header.append(reset);
    const canvas3d = el('canvas', { id: 'path3d' });
    const legend = el('div', { id: 'legend' });
    const box3d = el('div', { id: 'path3d-box' }, canvas3d, legend, el('div', { id: 'hint' }, 'drag: rotate · shift-drag: pan · wheel: zoom · double-click: reset'));
    const plotsBox = el('div', { id: 'plots-box' });
    const info = el('section', { id: 'info' }, el('h2', {}, 'at the cursor'), el('div', { id: 'info-body' }, 'Hover or click the path or a plot.'));
    const findings = el('section', { id: 'findings' }, el('h2', {}, `findings (${meta.findings.length})`));
    const peaks = el('section', { id: 'peaks' }, el('h2', {}, 'peaks'));
    document.body.append(header, el('main', {}, box3d, plotsBox, el('div', { id: 'below' }, info, findings, peaks)));
    state.info = info.querySelector('#info-body');
    buildFindings(state, findings);
    buildPeaks(state, peaks);
    setup3d(state, canvas3d, legend);
    setupPlots(state, plotsBox);
    window.addEventListener('resize', () => redrawAll(state));
  }

  function redrawAll(state) {
    state.draw3d();
    state.drawPlots();
  }

  function buildFindings(state, section) {
    const list = el('ol', {});
    for (const f of state.meta.findings) {
      const item = el('li', { class: f.violation ? 'violation' : '' }, `${f.label} — t=${fmt(f.time)} s, line ${f.line}`);
      item.addEventListener('click', () => jumpTo(state, f.time, f.motion));
      list.append(item);
    }
    if (!state.meta.findings.length) section.append('none');
    section.append(list);
  }

  function buildPeaks(state, section) {
    const s = summary(state);
    const table = el('table', { id: 'peaks-table' });
    const head = el('tr', {}, el('th', {}, 'axis'));
    s.motions.forEach((M, m) => {
      for (const name of ['velocity', 'acceleration', 'jerk']) head.append(el('th', {}, `|${name[0]}| ${s.motions.length > 1 ? 'AB'[m] : ''}`));
    });
    table.append(head);
    state.meta.axes.forEach((a) => {
      const row = el('tr', {}, el('td', {}, a));
      s.motions.forEach((M) => {
        for (const name of ['velocity', 'acceleration', 'jerk']) {
          const cell = el('td', { 'data-axis': a, 'data-quantity': name }, fmt(M.peaks[a][name], 3));
          cell.dataset.value = String(M.peaks[a][name]);
          row.append(cell);
        }
      });
      table.append(row);
    });
    section.append(table, el('div', {}, `units: ${state.meta.units}, s`));
  }

  function jumpTo(state, t, m) {
    const span = Math.max(state.total / 200, 1e-4);
    state.window = [Math.max(-span * 0.05, t - span), t + span];
    state.pinned = { t, m };
    showAt(state, t);
    redrawAll(state);
  }

  function showAt(state, t) {
    state.cursor = t;
    const rows = [];
    state.motions.forEach((M, m) => {
      if (!M.n) return;
      const i = spanAt(M, Math.min(Math.max(t, 0), M.total));
      const what = ['feed', 'rapid', 'dwell'][M.kind[i]];
      const text = textOf(M, M.line[i]);
      const p = position(M, i, t - M.start[i]);
      rows.push(el('div', {}, el('span', { class: 'k' }, `${M.name}: `), `t=${fmt(t, 6)} s · piece ${i + 1} of ${M.n} (${what}) · line ${M.line[i]} · ` + state.meta.axes.map((a, k) => `${a}=${fmt(p[k])}`).join(' ')));
      if (text !== undefined) rows.push(el('pre', {}, `${M.line[i]}: ${text}`));
    });
    state.info.replaceChildren(...rows);
  }

  function position(M, i, s) {
    const out = [];
    const c = new Float64Array(4);
    for (let k = 0; k < M.dim; k++) {
      const T = coeffs(M, i, k, c);
      out.push(valueAt(c, 0, Math.max(0, Math.min(T, s))));
    }
    return out;
  }

  // ---------------------------------------------------------------- 3D path
  function setup3d(state, canvas, legend) {
    const ctx = canvas.getContext('2d');
    const dim = state.dim;
    const axes3 = [];
    state.meta.axes.forEach((a, k) => { if ('XYZ'.includes(a) && axes3.length < 3) axes3.push(k); });
    if (!axes3.length) for (let k = 0; k < Math.min(3, dim); k++) axes3.push(k);
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const M of state.motions) {
      for (let i = 0; i <= M.n; i++) {
        axes3.forEach((k, j) => { const x = M.P[i * dim + k]; if (x < lo[j]) lo[j] = x; if (x > hi[j]) hi[j] = x; });
      }
    }
    for (let j = 0; j < 3; j++) if (!isFinite(lo[j])) { lo[j] = 0; hi[j] = 0; }
    const center = lo.map((l, j) => (l + hi[j]) / 2);
    const size = Math.max(...hi.map((h, j) => h - lo[j]), 1e-9);
    // The fastest speed of the feed pieces (at their ends, and their mean), for the colours.
    let vmax = 0;
    for (const M of state.motions) {
      for (let i = 0; i < M.n; i++) {
        if (M.kind[i] !== 0) continue;
        let at = 0, chord = 0;
        for (const k of axes3) {
          at += M.V[(i + 1) * dim + k] ** 2;
          chord += (M.P[(i + 1) * dim + k] - M.P[i * dim + k]) ** 2;
        }
        vmax = Math.max(vmax, Math.sqrt(at), Math.sqrt(chord) / (M.start[i + 1] - M.start[i]));
      }
    }
    vmax = vmax || 1;
    const flat = axes3.length < 3;
    // A drawing in a plane from above; a 3D path from the side and above.
    const cam = flat ? { yaw: 0, pitch: Math.PI / 2, zoom: 1, panX: 0, panY: 0 } : { yaw: -0.6, pitch: 0.9, zoom: 1, panX: 0, panY: 0 };
    const home = { ...cam };
    let dragging = null, quick = false, grid = null;
    legend.append(el('div', {}, `speed 0 … ${fmt(vmax, 3)} ${state.meta.units}/s`));
    const ramp = el('canvas', { width: '160', height: '8' });
    const rc = ramp.getContext('2d');
    for (let x = 0; x < 160; x++) { rc.fillStyle = speedColor(x / 159); rc.fillRect(x, 0, 1, 8); }
    legend.append(ramp);

    function project(W, H) {
      const s = (cam.zoom * (flat ? 0.85 : 0.6) * Math.min(W, H)) / size;
      const cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw), cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch);
      return (x, y, z, out) => {
        const dx = x - center[0], dy = y - center[1], dz = z - center[2];
        const rx = cy * dx - sy * dy, ry = sy * dx + cy * dy;
        out[0] = W / 2 + cam.panX + rx * s;
        out[1] = H / 2 + cam.panY - (cp * dz + sp * ry) * s;
      };
    }

    function draw() {
      const ratio = window.devicePixelRatio || 1;
      const W = canvas.clientWidth, H = canvas.clientHeight;
      if (canvas.width !== Math.round(W * ratio) || canvas.height !== Math.round(H * ratio)) {
        canvas.width = Math.round(W * ratio);
        canvas.height = Math.round(H * ratio);
      }
      ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
      ctx.clearRect(0, 0, W, H);
      const proj = project(W, H);
      const pt = [0, 0];
      const coord = (arr, i, j) => (axes3[j] === undefined ? 0 : arr[i * dim + axes3[j]]);
      if (state.showProgrammed) {
        // Under the motion, wide and light, so the programmed path shows beside it.
        ctx.lineWidth = 5;
        ctx.lineJoin = 'round';
        ctx.strokeStyle = 'rgba(120,120,120,0.35)';
        ctx.setLineDash([]);
        ctx.beginPath();
        for (const l of state.programmed) {
          if (l.rapid) continue;
          const n = l.pts.length / dim;
          for (let i = 0; i < n; i++) {
            proj(coord(l.pts, i, 0), coord(l.pts, i, 1), coord(l.pts, i, 2), pt);
            if (i === 0) ctx.moveTo(pt[0], pt[1]); else ctx.lineTo(pt[0], pt[1]);
          }
        }
        ctx.stroke();
      }
      grid = new Map();
      const [w0, w1] = state.window;
      const zoomed = w0 > 0 || w1 < state.total;
      // The second motion under the first, wider, so both show where they differ.
      for (let m = state.motions.length - 1; m >= 0; m--) {
        if (state.shown[m]) drawMotion(state.motions[m], m, proj, coord, W, H, zoomed, w0, w1);
      }
      const marker = state.cursor;
      if (marker !== null) {
        state.motions.forEach((M, m) => {
          if (!state.shown[m] || !M.n) return;
          const i = spanAt(M, Math.min(Math.max(marker, 0), M.total));
          const p = position(M, i, marker - M.start[i]);
          const at = (j) => (axes3[j] === undefined ? 0 : p[axes3[j]]);
          proj(at(0), at(1), at(2), pt);
          ctx.beginPath();
          ctx.arc(pt[0], pt[1], 5, 0, 2 * Math.PI);
          ctx.lineWidth = 2;
          ctx.strokeStyle = m === 0 ? '#000' : '#e07000';
          ctx.stroke();
        });
      }
    }

    function drawMotion(M, m, proj, coord, W, H, zoomed, w0, w1) {
      const pt = [0, 0], prev = [0, 0];
      const stride = quick ? Math.max(1, Math.floor(M.n / 150000)) : 1;
      const buckets = 24;
      const paths = [];
      for (let b = 0; b < buckets + 2; b++) paths.push(new Path2D());
      const c = [new Float64Array(4), new Float64Array(4), new Float64Array(4)];
      let last = -1, fixedBucket = -1;
      const bucketOf = (dist, dt) => fixedBucket >= 0 ? fixedBucket : Math.min(buckets - 1, Math.floor((dist / Math.max(dt, 1e-300) / vmax) * buckets));
      // A point under a pixel from the last one drawn, in the same colour, adds nothing.
      const hover = m === 0 || !state.shown[0];
      const add = (x, y, b, j) => {
        if (b === last && Math.abs(x - prev[0]) + Math.abs(y - prev[1]) < 0.6) return;
        if (b !== last) paths[b].moveTo(prev[0], prev[1]);
        paths[b].lineTo(x, y);
        last = b;
        prev[0] = x; prev[1] = y;
        if (hover) {
          const gx = Math.floor(x / 6), gy = Math.floor(y / 6);
          if (gx >= 0 && gy >= 0 && gx < W && gy < H) grid.set(gx * 100000 + gy, [m, j]);
        }
      };
      proj(coord(M.P, 0, 0), coord(M.P, 0, 1), coord(M.P, 0, 2), prev);
      for (let i = 0; i < M.n; i += stride) {
        const j = Math.min(M.n, i + stride);
        const kind = M.kind[i];
        proj(coord(M.P, j, 0), coord(M.P, j, 1), coord(M.P, j, 2), pt);
        const outside = zoomed && (M.start[j] < w0 || M.start[i] > w1);
        if (kind === 2) continue;
        if (kind === 1 && state.rapids === 'hidden') { prev[0] = pt[0]; prev[1] = pt[1]; last = -1; continue; }
        const T = M.start[j] - M.start[i];
        fixedBucket = outside || (kind === 1 && state.rapids === 'faded') ? buckets + 1 : m > 0 ? buckets : -1;
        const len = Math.abs(pt[0] - prev[0]) + Math.abs(pt[1] - prev[1]);
        if (stride === 1 && len > 6) {
          // A long piece: drawn along its cubic, each part by its own speed.
          for (let a = 0; a < 3; a++) if (axes3[a] !== undefined) coeffs(M, i, axes3[a], c[a]);
          const steps = Math.min(32, Math.ceil(len / 3));
          const q = [0, 0], was = [0, 0, 0], now = [0, 0, 0];
          const at = (a, u) => (axes3[a] === undefined ? 0 : valueAt(c[a], 0, u));
          for (let a = 0; a < 3; a++) was[a] = at(a, 0);
          for (let s = 1; s <= steps; s++) {
            const u = (s / steps) * T;
            for (let a = 0; a < 3; a++) now[a] = at(a, u);
            const dist = Math.hypot(now[0] - was[0], now[1] - was[1], now[2] - was[2]);
            if (s < steps) proj(now[0], now[1], now[2], q); else { q[0] = pt[0]; q[1] = pt[1]; }
            add(q[0], q[1], bucketOf(dist, T / steps), j);
            for (let a = 0; a < 3; a++) was[a] = now[a];
          }
        } else {
          let dist = 0;
          for (let a = 0; a < 3; a++) if (axes3[a] !== undefined) dist += (M.P[j * dim + axes3[a]] - M.P[i * dim + axes3[a]]) ** 2;
          add(pt[0], pt[1], bucketOf(Math.sqrt(dist), T), j);
        }
      }
      ctx.setLineDash([]);
      for (let b = 0; b < buckets + 2; b++) {
        if (b === buckets + 1) { ctx.strokeStyle = 'rgba(150,150,150,0.35)'; ctx.lineWidth = 1; }
        else if (b === buckets) { ctx.strokeStyle = 'rgba(240,130,20,0.75)'; ctx.lineWidth = 4; }
        else { ctx.strokeStyle = speedColor((b + 0.5) / buckets); ctx.lineWidth = 1.6; }
        ctx.stroke(paths[b]);
      }
    }

    let pending = false;
    state.draw3d = () => {
      if (pending) return;
      pending = true;
      requestAnimationFrame(() => { pending = false; draw(); });
    };
    state.draw3dNow = draw;
    canvas.addEventListener('mousedown', (e) => { dragging = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2, moved: false }; });
    window.addEventListener('mouseup', () => {
      if (dragging && dragging.moved) { quick = false; state.draw3d(); }
      dragging = null;
    });
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('mousemove', (e) => {
      if (dragging) {
        const dx = e.clientX - dragging.x, dy = e.clientY - dragging.y;
        dragging.x = e.clientX; dragging.y = e.clientY; dragging.moved = true;
        if (dragging.pan) { cam.panX += dx; cam.panY += dy; } else { cam.yaw += dx * 0.01; cam.pitch = Math.max(-Math.PI, Math.min(Math.PI, cam.pitch + dy * 0.01)); }
        quick = true;
        state.draw3d();
        return;
      }
      if (!grid) return;
      const r = canvas.getBoundingClientRect();
      const gx = Math.floor((e.clientX - r.left) / 6), gy = Math.floor((e.clientY - r.top) / 6);
      for (const [ox, oy] of [[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [-1, -1], [1, -1], [-1, 1]]) {
        const hit = grid.get((gx + ox) * 100000 + gy + oy);
        if (hit) {
          showAt(state, state.motions[hit[0]].start[hit[1]]);
          state.drawPlots();
          state.draw3d();
          return;
        }
      }
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      const f = e.deltaY < 0 ? 1.2 : 1 / 1.2;
      const r = canvas.getBoundingClientRect();
      const mx = e.clientX - r.left - canvas.clientWidth / 2 - cam.panX, my = e.clientY - r.top - canvas.clientHeight / 2 - cam.panY;
      cam.panX -= mx * (f - 1); cam.panY -= my * (f - 1);
      cam.zoom *= f;
      state.draw3d();
    }, { passive: false });
    canvas.addEventListener('dblclick', () => { Object.assign(cam, home); state.draw3d(); });
  }

  // ---------------------------------------------------------------- plots
  function setupPlots(state, box) {
    const rows = QUANTITIES.map((name, q) => ({ name, q }));
    if (state.meta.difference) rows.push({ name: 'difference', q: -1 });
    const canvases = rows.map(() => el('canvas', {}));
    box.append(...canvases);
    const margin = { left: 64, right: 10, top: 14, bottom: 16 };
    const lo = new Float64Array(4096), hi = new Float64Array(4096), r2 = new Float64Array(2);
    let drag = null;

    function toTime(x, W) {
      const [w0, w1] = state.window;
      return w0 + ((x - margin.left) / Math.max(1, W - margin.left - margin.right)) * (w1 - w0);
    }

    function drawRow(row, canvas) {
      const ratio = window.devicePixelRatio || 1;
      const W = canvas.clientWidth, H = canvas.clientHeight;
      if (canvas.width !== Math.round(W * ratio) || canvas.height !== Math.round(H * ratio)) {
        canvas.width = Math.round(W * ratio);
        canvas.height = Math.round(H * ratio);
      }
      const ctx = canvas.getContext('2d');
      ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
      ctx.clearRect(0, 0, W, H);
      const plotW = Math.max(1, Math.floor(W - margin.left - margin.right)), plotH = H - margin.top - margin.bottom;
      const [w0, w1] = state.window;
      const dt = (w1 - w0) / plotW;
      const series = [];
      let ymin = Infinity, ymax = -Infinity;
      if (row.q >= 0) {
        state.motions.forEach((M, m) => {
          if (!state.shown[m]) return;
          for (let k = 0; k < state.dim; k++) {
            const l = new Float64Array(plotW), h = new Float64Array(plotW);
            for (let x = 0; x < plotW; x++) {
              rangeOf(M, row.q, k, w0 + x * dt, w0 + (x + 1) * dt, r2);
              l[x] = r2[0]; h[x] = r2[1];
              if (r2[0] < ymin) ymin = r2[0];
              if (r2[1] > ymax) ymax = r2[1];
            }
            series.push({ l, h, color: COLORS[k % COLORS.length], dashed: m > 0 });
          }
        });
        const limitName = ['', 'velocity', 'acceleration', 'jerk'][row.q];
        row.limits = [];
        state.meta.axes.forEach((a, k) => {
          const lim = state.meta.limits[a] && state.meta.limits[a][limitName];
          if (lim) { row.limits.push([lim, COLORS[k % COLORS.length]]); ymin = Math.min(ymin, -lim); ymax = Math.max(ymax, lim); }
        });
      } else {
        const d = state.meta.difference;
        const l = new Float64Array(plotW), h = new Float64Array(plotW);
        const n = d.bins.length, bw = d.end / n;
        for (let x = 0; x < plotW; x++) {
          const a = Math.max(0, Math.floor((w0 + x * dt) / bw)), b = Math.min(n - 1, Math.floor((w0 + (x + 1) * dt) / bw));
          let v = 0;
          for (let i = a; i <= b; i++) v = Math.max(v, d.bins[i]);
          l[x] = 0; h[x] = v;
          ymax = Math.max(ymax, v);
        }
        ymin = 0;
        ymax = Math.max(ymax, d.tolerance * 1.2);
        series.push({ l, h, color: '#b3261e', dashed: false });
        row.limits = [[d.tolerance, '#555']];
      }
      if (!isFinite(ymin)) { ymin = -1; ymax = 1; }
      if (ymax - ymin < 1e-12 * Math.max(1, Math.abs(ymax))) { ymin -= 1; ymax += 1; }
      const pad = (ymax - ymin) * 0.06;
      ymin -= pad; ymax += pad;
      const Y = (v) => margin.top + plotH - ((v - ymin) / (ymax - ymin)) * plotH;
      ctx.strokeStyle = '#e3e6eb';
      ctx.lineWidth = 1;
      ctx.font = '11px system-ui, sans-serif';
      ctx.fillStyle = '#5a6272';
      for (let i = 0; i <= 4; i++) {
        const v = ymin + ((ymax - ymin) * i) / 4;
        ctx.beginPath(); ctx.moveTo(margin.left, Y(v)); ctx.lineTo(margin.left + plotW, Y(v)); ctx.stroke();
        ctx.fillText(fmt(v, 3), 2, Y(v) + 4);
      }
      ctx.save();
      ctx.beginPath();
      ctx.rect(margin.left, margin.top, plotW, plotH);
      ctx.clip();
      for (const [lim, color] of row.limits) {
        ctx.setLineDash([5, 4]);
        ctx.strokeStyle = color;
        for (const v of row.q >= 0 ? [lim, -lim] : [lim]) { ctx.beginPath(); ctx.moveTo(margin.left, Y(v)); ctx.lineTo(margin.left + plotW, Y(v)); ctx.stroke(); }
      }
      // The second motion first, under the first's axis colours.
      for (const s of series.slice().reverse()) {
        ctx.setLineDash(s.dashed ? [4, 3] : []);
        ctx.strokeStyle = s.dashed ? 'rgba(224,112,0,0.9)' : s.color;
        ctx.fillStyle = ctx.strokeStyle;
        ctx.lineWidth = 1.2;
        ctx.beginPath();
        let open = false;
        for (let x = 0; x < plotW; x++) {
          if (!isFinite(s.l[x])) { open = false; continue; }
          const X = margin.left + x + 0.5;
          if (!open) { ctx.moveTo(X, Y(s.h[x])); open = true; } else ctx.lineTo(X, Y(s.h[x]));
          if (s.h[x] - s.l[x] > 0) ctx.lineTo(X, Y(s.l[x]));
        }
        ctx.stroke();
      }
      ctx.setLineDash([]);
      if (state.cursor !== null && state.cursor >= w0 && state.cursor <= w1) {
        const X = margin.left + ((state.cursor - w0) / (w1 - w0)) * plotW;
        ctx.strokeStyle = '#000';
        ctx.beginPath(); ctx.moveTo(X, margin.top); ctx.lineTo(X, margin.top + plotH); ctx.stroke();
      }
      ctx.restore();
      ctx.fillStyle = '#1d2330';
      const unit = state.meta.units;
      const units = { position: unit, velocity: `${unit}/s`, acceleration: `${unit}/s²`, jerk: `${unit}/s³`, difference: state.meta.difference ? state.meta.difference.unit : '' };
      ctx.fillText(`${row.name} (${units[row.name]})` + (row.q >= 0 ? '  ' + state.meta.axes.map((a) => a).join(' ') : ''), margin.left + 4, 11);
      if (row.q >= 0) {
        let x = margin.left + 4 + ctx.measureText(`${row.name} (${units[row.name]})  `).width;
        state.meta.axes.forEach((a, k) => { ctx.fillStyle = COLORS[k % COLORS.length]; ctx.fillText(a, x, 11); x += ctx.measureText(a + ' ').width; });
      }
      if (row === rows[rows.length - 1]) {
        ctx.fillStyle = '#5a6272';
        ctx.fillText(`t = ${fmt(w0, 4)} s`, margin.left, H - 3);
        const end = `${fmt(w1, 4)} s`;
        ctx.fillText(end, margin.left + plotW - ctx.measureText(end).width, H - 3);
      }
    }

    let pending = false;
    state.drawPlots = () => {
      if (pending) return;
      pending = true;
      requestAnimationFrame(() => { pending = false; rows.forEach((row, i) => drawRow(row, canvases[i])); });
    };
    state.drawPlotsNow = () => rows.forEach((row, i) => drawRow(row, canvases[i]));
    for (const canvas of canvases) {
      canvas.addEventListener('wheel', (e) => {
        e.preventDefault();
        const r = canvas.getBoundingClientRect();
        const t = toTime(e.clientX - r.left, canvas.clientWidth);
        const f = e.deltaY < 0 ? 1 / 1.25 : 1.25;
        const [w0, w1] = state.window;
        const width = Math.max((w1 - w0) * f, 1e-6);
        const left = t - (t - w0) * (width / (w1 - w0));
        state.window = [left, left + width];
        redrawAll(state);
      }, { passive: false });
      canvas.addEventListener('mousedown', (e) => { drag = { x: e.clientX, w: state.window.slice(), W: canvas.clientWidth, moved: false }; });
      canvas.addEventListener('mousemove', (e) => {
        const r = canvas.getBoundingClientRect();
        if (drag && e.buttons) {
          const dx = e.clientX - drag.x;
          if (Math.abs(dx) > 2) drag.moved = true;
          const span = drag.w[1] - drag.w[0];
          const shift = (-dx / Math.max(1, drag.W - margin.left - margin.right)) * span;
          state.window = [drag.w[0] + shift, drag.w[1] + shift];
          redrawAll(state);
          return;
        }
        if (state.pinned) return;
        showAt(state, toTime(e.clientX - r.left, canvas.clientWidth));
        redrawAll(state);
      });
      canvas.addEventListener('mouseup', (e) => {
        if (drag && !drag.moved) {
          const r = canvas.getBoundingClientRect();
          const t = toTime(e.clientX - r.left, canvas.clientWidth);
          state.pinned = state.pinned ? null : { t };
          showAt(state, t);
          redrawAll(state);
        }
        drag = null;
      });
      canvas.addEventListener('dblclick', () => { state.window = [0, state.total]; state.pinned = null; redrawAll(state); });
    }
  }

  view.ready = main().catch((e) => {
    document.body.append(el('div', { id: 'error' }, `pvtc view: ${e && e.message ? e.message : e}`));
    throw e;
  });
})();
