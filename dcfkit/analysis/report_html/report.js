'use strict';
/* dcfkit report page: draws the tables, SVG plots, frames and provenance of the JSON block
   #report-data. User text only ever becomes text nodes (textContent), never markup. */
(function () {
  const data = JSON.parse(document.getElementById('report-data').textContent);
  const trackers = data.trackers;
  /* the SVG namespace, read from the HTML parser, so that the page holds no URL at all */
  const SVG = (function () {
    const t = document.createElement('template');
    t.innerHTML = '<svg></svg>';
    return t.content.firstChild.namespaceURI;
  })();
  const PALETTE = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f',
    '#bcbd22', '#17becf'];
  const DASHES = ['', '6 3', '2 3', '9 3 2 3'];
  const colour = (t) => PALETTE[t % PALETTE.length];
  const dash = (t) => DASHES[Math.floor(t / PALETTE.length) % DASHES.length];
  const safeKey = (k) => String(k).replace(/[^A-Za-z0-9_-]/g, '_');

  function h(tag, props, ...children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(props || {})) {
      if (k === 'text') node.textContent = v;
      else if (k === 'class') node.className = v;
      else if (k.startsWith('on')) node.addEventListener(k.slice(2), v);
      else node.setAttribute(k, v);
    }
    for (const c of children) if (c !== null && c !== undefined) node.append(c);
    return node;
  }

  function s(tag, attrs, parent) {
    const node = document.createElementNS(SVG, tag);
    for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
    if (parent) parent.append(node);
    return node;
  }

  function fmt(v, digits) {
    if (v === null || v === undefined) return '\u2013';
    return typeof v === 'number' ? v.toFixed(digits) : String(v);
  }

  const swatch = (t) => h('span', {class: 'sw', style: 'background:' + colour(t)});

  /* ---------------------------------------------------------------- legend toggles */
  const hidden = new Set();
  const hideStyle = h('style');
  document.head.append(hideStyle);

  function toggle(key) {
    if (hidden.has(key)) hidden.delete(key); else hidden.add(key);
    hideStyle.textContent = [...hidden].map((k) =>
      `.s-${k}{display:none}.l-${k}{opacity:.45;text-decoration:line-through}`).join('\n');
  }

  /* ---------------------------------------------------------------- tooltip */
  const tip = h('div', {class: 'tip', role: 'tooltip'});
  document.body.append(tip);

  function showTip(event, title, rows) {
    tip.replaceChildren(h('div', {class: 'tip-title', text: title}),
      ...rows.map(([col, label, value]) => h('div', {class: 'tip-row'},
        h('span', {class: 'sw', style: 'background:' + col}), h('span', {text: label}),
        h('span', {class: 'num', text: value}))));
    tip.style.display = 'block';
    const w = tip.offsetWidth, hgt = tip.offsetHeight;
    const x = event.clientX + 16 + w > window.innerWidth ? event.clientX - 16 - w : event.clientX + 16;
    const y = Math.min(event.clientY + 16, window.innerHeight - hgt - 4);
    tip.style.left = Math.max(4, x) + 'px';
    tip.style.top = Math.max(4, y) + 'px';
  }
  const hideTip = () => { tip.style.display = 'none'; };

  /* ---------------------------------------------------------------- charts */
  function niceTicks(lo, hi, n) {
    const span = hi - lo;
    if (!(span > 0)) return [lo];
    const raw = span / n, mag = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 2.5, 5, 10].map((f) => f * mag).find((st) => st >= raw * 0.999);
    const out = [];
    for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) out.push(+v.toFixed(10));
    return out;
  }

  function yRange(series) {
    const vals = [];
    for (const se of series) for (const arr of [se.y, se.low || [], se.high || []]) {
      for (const v of arr) if (v !== null) vals.push(v);
    }
    if (!vals.length) return [0, 1];
    let lo = Math.min(...vals), hi = Math.max(...vals);
    const pad = Math.max((hi - lo) * 0.15, 0.01);
    return [Math.max(0, lo - pad), Math.min(1, hi + pad)];
  }

  function linePath(points) {
    let d = '', pen = false;
    for (const p of points) {
      if (p === null) { pen = false; continue; }
      d += (pen ? 'L' : 'M') + p[0].toFixed(1) + ',' + p[1].toFixed(1);
      pen = true;
    }
    return d;
  }

  function seriesStyle(se) {
    return se.t !== undefined ? {col: colour(se.t), dash: dash(se.t), key: safeKey(se.key)}
      : {col: se.color, dash: '', key: safeKey(se.key)};
  }

  /* a chart's x values are shared (spec.x), or each series has its own (se.x: a precision-recall
     curve, whose recall differs per tracker); se.point marks one point of a series */
  function chart(spec) {
    const W = spec.small ? 300 : 400, H = spec.small ? 220 : 290;
    const m = {l: 46, r: 12, t: 10, b: 40};
    const xs = spec.x;
    const xsOf = (se) => se.x || xs;
    const allX = xs || spec.series.flatMap((se) => se.x).filter((v) => v !== null);
    const [x0, x1] = spec.xlim || [Math.min(...allX), Math.max(...allX)];
    const [y0, y1] = spec.ylim || yRange(spec.series);
    const px = (v) => m.l + (v - x0) / ((x1 - x0) || 1) * (W - m.l - m.r);
    const py = (v) => H - m.b - (v - y0) / ((y1 - y0) || 1) * (H - m.t - m.b);
    const svg = s('svg', {viewBox: `0 0 ${W} ${H}`, class: 'chart', role: 'img'});
    for (const v of niceTicks(y0, y1, 5)) {
      s('line', {x1: m.l, x2: W - m.r, y1: py(v), y2: py(v), class: 'grid'}, svg);
      s('text', {x: m.l - 5, y: py(v) + 3.5, class: 'tick', 'text-anchor': 'end'}, svg).textContent = String(+v.toFixed(3));
    }
    const xticks = spec.xticks || niceTicks(x0, x1, 5).map((v) => [v, String(+v.toFixed(3))]);
    for (const [v, label] of xticks) {
      s('line', {x1: px(v), x2: px(v), y1: m.t, y2: H - m.b, class: 'grid'}, svg);
      s('text', {x: px(v), y: H - m.b + 14, class: 'tick', 'text-anchor': 'middle'}, svg).textContent = label;
    }
    s('rect', {x: m.l, y: m.t, width: W - m.l - m.r, height: H - m.t - m.b, class: 'frame'}, svg);
    s('text', {x: (m.l + W - m.r) / 2, y: H - 6, class: 'axis', 'text-anchor': 'middle'}, svg).textContent = spec.xlabel;
    s('text', {x: 12, y: (m.t + H - m.b) / 2, class: 'axis', 'text-anchor': 'middle',
      transform: `rotate(-90 12 ${(m.t + H - m.b) / 2})`}, svg).textContent = spec.ylabel;
    if (spec.vline) {
      s('line', {x1: px(spec.vline.x), x2: px(spec.vline.x), y1: m.t, y2: H - m.b, class: 'vline'}, svg);
    }
    const plot = s('g', {}, svg);
    for (const se of [...spec.series].reverse()) {  /* the best drawn last, on top */
      const st = seriesStyle(se), sx = xsOf(se);
      const g = s('g', {class: 's-' + st.key}, plot);
      if (se.low && se.high) {
        const up = se.high.map((v, i) => v === null ? null : [px(xs[i]), py(v)]).filter(Boolean);
        const down = se.low.map((v, i) => v === null ? null : [px(xs[i]), py(v)]).filter(Boolean).reverse();
        s('polygon', {points: up.concat(down).map((p) => p.join(',')).join(' '), fill: st.col, opacity: 0.15}, g);
      }
      const pts = se.y.map((v, i) => v === null || sx[i] === null ? null : [px(sx[i]), py(v)]);
      s('path', {d: linePath(pts), class: 'line', stroke: st.col, 'stroke-dasharray': st.dash}, g);
      if (se.marker) for (const p of pts) if (p) s('circle', {cx: p[0], cy: p[1], r: 3, fill: st.col}, g);
      if (se.point) s('circle', {cx: px(se.point[0]), cy: py(se.point[1]), r: 4.5, fill: st.col, class: 'point'}, g);
    }
    const guide = s('line', {y1: m.t, y2: H - m.b, class: 'guide', visibility: 'hidden'}, svg);
    const overlay = s('rect', {x: m.l, y: m.t, width: W - m.l - m.r, height: H - m.t - m.b, class: 'overlay'}, svg);
    overlay.addEventListener('pointermove', (event) => {
      const box = svg.getBoundingClientRect();
      const sx = (event.clientX - box.left) * W / box.width;
      const nearest = (arr) => {  /* the index of the x nearest the pointer */
        let best = 0;
        arr.forEach((v, i) => {
          if (v !== null && (arr[best] === null || Math.abs(px(v) - sx) < Math.abs(px(arr[best]) - sx))) best = i;
        });
        return best;
      };
      const best = xs ? nearest(xs) : 0;
      const gx = xs ? px(xs[best]) : Math.min(Math.max(sx, m.l), W - m.r);
      guide.setAttribute('x1', gx);
      guide.setAttribute('x2', gx);
      guide.setAttribute('visibility', 'visible');
      const at = (se) => se.x ? nearest(se.x) : best;
      const rows = spec.series.filter((se) => !hidden.has(safeKey(se.key)) && se.y[at(se)] !== null)
        .map((se) => [seriesStyle(se).col, se.t !== undefined ? trackers[se.t] : se.label, se.y[at(se)]])
        .sort((a, b) => b[2] - a[2]).map(([c, l, v]) => [c, l, fmt(v, 3)]);
      const xValue = xs ? xs[best] : x0 + (gx - m.l) / (W - m.l - m.r) * (x1 - x0);
      const xName = spec.xticks ? (spec.xticks.find((t) => t[0] === xValue) || [0, xValue])[1] : fmt(xValue, 2);
      showTip(event, `${spec.xlabel}: ${xName}`, rows);
    });
    overlay.addEventListener('pointerleave', () => { guide.setAttribute('visibility', 'hidden'); hideTip(); });
    const legend = h('div', {class: 'legend'});
    for (const se of spec.series) {
      const st = seriesStyle(se);
      legend.append(h('button', {type: 'button', class: 'lg l-' + st.key, title: 'show or hide',
        onclick: () => toggle(st.key)}, h('span', {class: 'sw', style: 'background:' + st.col}),
      h('span', {text: se.label})));
    }
    if (spec.vline) legend.append(h('span', {class: 'lg note', text: spec.vline.label}));
    return h('figure', {class: spec.small ? 'fig small' : 'fig'}, h('figcaption', {text: spec.title}), svg, legend);
  }

  function charts(spec) {
    return h('div', {class: 'charts'}, ...spec.charts.map(chart));
  }

  /* ---------------------------------------------------------------- tables */
  /* a mean, its confidence interval as a bar on the column's scale, '*' if significant */
  function intervalCell(col, v) {
    if (!v) return h('td', {class: 'num'});
    const [mean, low, high, significant] = v;
    const width = 90, span = (col.domain[1] - col.domain[0]) || 1;
    const x = (value) => (4 + (width - 8) * (value - col.domain[0]) / span).toFixed(1);
    const bar = s('svg', {class: 'ci', width: width, height: 10, 'aria-hidden': 'true'});
    if (col.domain[0] <= 0 && col.domain[1] >= 0) s('line', {class: 'zero', x1: x(0), x2: x(0), y1: 0, y2: 10}, bar);
    const known = low !== null && high !== null;
    if (known) s('line', {class: 'bar', x1: x(low), x2: x(high), y1: 5, y2: 5}, bar);
    if (mean !== null) s('circle', {cx: x(mean), cy: 5, r: 2.5}, bar);
    const text = fmt(mean, col.digits) + (known ? ` [${fmt(low, col.digits)}, ${fmt(high, col.digits)}]` : '')
      + (significant ? ' *' : '');
    return h('td', {class: 'num interval'}, h('span', {text: text}), bar);
  }

  function cell(col, v) {
    if (col.type === 'interval') return intervalCell(col, v);
    if (col.type === 'tracker') return h('td', {class: 'tracker'}, swatch(v), h('span', {text: trackers[v]}));
    if (col.type === 'lines') return h('td', {class: 'lines'}, ...(v || []).map((line) => h('div', {text: line})));
    if (col.type === 'num') return h('td', {class: 'num', text: fmt(v, col.digits)});
    return h('td', {text: v === null || v === undefined ? '' : String(v)});
  }

  function compare(a, b, desc) {
    const na = a === null || a === undefined, nb = b === null || b === undefined;
    if (na || nb) return na - nb;  /* missing values last, either way */
    const c = typeof a === 'number' && typeof b === 'number' ? a - b
      : String(a).localeCompare(String(b), undefined, {numeric: true});
    return desc ? -c : c;
  }

  function table(spec) {
    const head = h('tr'), body = h('tbody');
    const rows = spec.rows.map((r) => {
      const tr = h('tr', {}, ...r.map((v, j) => cell(spec.columns[j], v)));
      tr.dataRow = r;
      return tr;
    });
    body.append(...rows);
    let current = {col: -1, desc: false};
    const sortBy = (j) => {
      const col = spec.columns[j];
      const desc = current.col === j ? !current.desc : col.type === 'num' || col.type === 'interval';
      current = {col: j, desc: desc};
      const value = (tr) => col.type === 'tracker' ? trackers[tr.dataRow[j]]
        : col.type === 'lines' ? (tr.dataRow[j] || []).join(' ')
        : col.type === 'interval' ? (tr.dataRow[j] || [null])[0] : tr.dataRow[j];
      rows.sort((a, b) => compare(value(a), value(b), desc));
      body.append(...rows);
      head.querySelectorAll('th').forEach((th, k) =>
        th.setAttribute('aria-sort', k === j ? (desc ? 'descending' : 'ascending') : 'none'));
    };
    spec.columns.forEach((col, j) => head.append(h('th', {class: col.type, scope: 'col', 'aria-sort': 'none'},
      h('button', {type: 'button', text: col.label, title: 'sort', onclick: () => sortBy(j)}))));
    const tbl = h('table', {class: 'data', id: spec.id + '-table'}, h('thead', {}, head), body);
    const parts = [];
    if (spec.filter) parts.push(filterBox(rows, (tr) => tr.textContent, spec.rows.length, 'rows'));
    parts.push(h('div', {class: spec.filter ? 'scroll long' : 'scroll'}, tbl));
    return h('div', {}, ...parts);
  }

  function filterBox(items, textOf, total, noun) {
    const count = h('span', {class: 'count', text: `${total} ${noun}`});
    const texts = new Map(items.map((it) => [it, textOf(it).toLowerCase()]));
    const input = h('input', {type: 'search', placeholder: 'filter: sequence, tracker, attribute\u2026',
      'aria-label': 'filter'});
    input.addEventListener('input', () => {
      const q = input.value.trim().toLowerCase();
      let shown = 0;
      for (const it of items) {
        it.hidden = q !== '' && !texts.get(it).includes(q);
        if (!it.hidden) shown += 1;
      }
      count.textContent = q ? `${shown} of ${total} ${noun}` : `${total} ${noun}`;
    });
    return h('div', {class: 'filter'}, input, count);
  }

  /* ---------------------------------------------------------------- frames */
  function thumb(th) {
    const svg = s('svg', {viewBox: `0 0 ${th.w} ${th.h}`, width: th.w, height: th.h, class: 'thumb'});
    s('image', {width: th.w, height: th.h, href: 'data:image/jpeg;base64,' + th.jpeg, decoding: 'async'}, svg);
    th.boxes.forEach((b, t) => {
      if (b) {
        s('rect', {x: b[0], y: b[1], width: b[2], height: b[3], class: 'box s-t' + t, stroke: colour(t),
          'stroke-dasharray': dash(t)}, svg);
      }
    });
    if (th.gt) {
      s('rect', {x: th.gt[0], y: th.gt[1], width: th.gt[2], height: th.gt[3], class: 'gt-under'}, svg);
      s('rect', {x: th.gt[0], y: th.gt[1], width: th.gt[2], height: th.gt[3], class: 'gt'}, svg);
    }
    const lines = [`frame ${th.frame}` + (th.zoom > 1.01 ? `, zoomed \u00d7${th.zoom}` : ', whole frame')];
    th.iou.forEach((v, t) => lines.push(`${trackers[t]}: IoU ${v === null ? 'not scored' : fmt(v, 2)}`));
    s('title', {}, svg).textContent = lines.join('\n');
    return h('figure', {class: 'th'}, svg, h('figcaption', {text: `#${th.frame}`}));
  }

  function gallery(spec) {
    const cards = spec.cards.map((card) => h('article', {class: 'card'},
      h('div', {class: 'info'},
        h('h3', {text: card.name}),
        h('p', {class: 'meta', text: `${card.frames} frames` + (card.attributes.length ? ' \u00b7 ' +
          card.attributes.join(' ') : '')}),
        h('div', {class: 'scores'}, h('span', {class: 'meta', text: 'AUC'}), ...card.auc.map((v, t) =>
          h('span', {class: 'sc s-t' + t}, swatch(t), h('span', {text: `${trackers[t]} ${fmt(v, 3)}`}))))),
      h('div', {class: 'thumbs'}, ...card.thumbs.map(thumb))));
    const box = filterBox(cards, (c) => c.querySelector('h3').textContent + ' ' +
      c.querySelector('.meta').textContent, cards.length, 'sequences');
    return h('div', {}, box, h('div', {class: 'cards'}, ...cards));
  }

  /* ---------------------------------------------------------------- provenance */
  function counted(list) {
    if (!list || !list.length) return [h('div', {text: 'not recorded'})];
    return list.map(([value, n]) => h('div', {}, h('code', {text: value}),
      list.length > 1 ? h('span', {class: 'n', text: ` (${n} sequences)`}) : null));
  }

  function entry(dl, label, ...values) {
    dl.append(h('dt', {text: label}), h('dd', {}, ...values));
  }

  function provenance(spec) {
    const out = h('div', {class: 'prov'});
    const here = h('dl');
    entry(here, 'command', h('code', {text: spec.report.command}));
    entry(here, 'dcfkit', h('code', {text: spec.report.dcfkit}));
    entry(here, 'machine', h('code', {text: spec.report.machine}));
    entry(here, 'platform', h('code', {text: spec.report.platform}));
    entry(here, 'written', h('code', {text: spec.report.time}));
    for (const [label, value] of spec.extra) entry(here, label, h('code', {text: value}));
    out.append(h('h3', {text: 'This page'}), here);
    for (const tr of spec.trackers) {
      const dl = h('dl');
      entry(dl, 'folder', h('code', {text: tr.folder}));
      if (!tr.sequences) {
        entry(dl, 'recorded', h('span', {text: 'nothing: result files without dcfkit sidecars (imported)'}));
      } else {
        entry(dl, 'sidecars', h('span', {text: String(tr.sequences)}));
        entry(dl, 'run key (config hash)', ...counted(tr.run_keys));
        entry(dl, 'dcfkit', ...counted(tr.versions));
        entry(dl, 'plugins', ...counted(tr.plugins));
        entry(dl, 'source', ...counted(tr.sources || []));
        entry(dl, 'command', ...counted(tr.commands));
        entry(dl, 'machine', ...counted(tr.machines));
        entry(dl, 'platform', ...counted(tr.platforms || []));
        entry(dl, 'run', h('code', {text: tr.times.join(' to ')}));
        if (tr.config) {
          entry(dl, 'config', h('details', {}, h('summary', {text: 'resolved config'}),
            h('pre', {text: JSON.stringify(tr.config, null, 1)})));
        }
      }
      out.append(h('h3', {}, swatch(tr.t), h('span', {text: trackers[tr.t]})), dl);
    }
    return out;
  }

  /* ---------------------------------------------------------------- groups */
  /* several parts in one section (a table, another, a chart), each with its own title and note */
  function group(spec) {
    return h('div', {class: 'group'}, ...spec.parts.map((part) => h('div', {class: 'part'},
      part.title ? h('h3', {text: part.title}) : null, part.note ? h('p', {class: 'note', text: part.note}) : null,
      DRAW[part.kind](part))));
  }

  /* ---------------------------------------------------------------- page */
  const DRAW = {table: table, charts: charts, gallery: gallery, provenance: provenance, group: group};
  const main = document.getElementById('main');
  const nav = document.getElementById('nav');
  for (const sec of data.sections) {
    const id = safeKey(sec.id);
    nav.append(h('a', {href: '#' + id, text: sec.title}));
    main.append(h('section', {id: id}, h('h2', {text: sec.title}),
      sec.note ? h('p', {class: 'note', text: sec.note}) : null, DRAW[sec.kind](sec)));
  }
})();
