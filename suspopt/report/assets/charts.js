(function () {
  "use strict";
  const SAME = window.suspoptSettings.same, GAP = window.suspoptSettings.labelGapPx;

  function peak(c) { return c.reduce((m, v) => (v === null ? m : Math.max(m, Math.abs(v))), 0); }
  function same(a, b) {
    if (a.length !== b.length) return false;
    const tol = SAME * Math.max(peak(a), peak(b));
    return a.every((v, k) => (v === null || b[k] === null ? v === b[k] : Math.abs(v - b[k]) <= tol));
  }
  // the indices of the curves in groups of the same curve, in the curves' order
  function distinct(curves) {
    const groups = [];
    curves.forEach((c, k) => {
      const g = groups.find(g => same(curves[g[0]], c));
      if (g) g.push(k); else groups.push([k]);
    });
    return groups;
  }
  function lines(x, curves, labels, prefix, extra) {
    return distinct(curves).map(g => Object.assign({ type: "scatter", mode: "lines", x: x,
      y: curves[g[0]], name: prefix + g.map(k => labels[k]).join(", "), meta: { members: g } }, extra || {}));
  }

  function axisTitle(name, unit) { return { text: unit ? name + " [" + unit + "]" : name }; }
  // a series of one value, about it (plotly's own range of one value may span [v - 1, v + 1],
  // where 0.007 lies flat at 0)
  function flat(y) {
    const v = y.filter(x => x !== null);
    if (!v.length || v.some(x => x !== v[0])) return {};
    const pad = Math.abs(v[0]) * 0.05 || 1;
    return { range: [v[0] - pad, v[0] + pad] };
  }
  function history(div, h) {
    const panels = (h.best || []).map((b, j) => [b, "best " + h.best_names[j], (h.best_units || [])[j]]);
    if (h.hypervolume && h.hypervolume.some(v => v !== null))
      panels.push([h.hypervolume, "hypervolume (normalised)", "1"]);
    if (h.feasible) panels.push([h.feasible, "feasible share", "1"]);
    const columns = panels.length > 4 ? 3 : Math.min(2, panels.length);
    const rows = Math.ceil(panels.length / columns), height = 80 + 240 * rows;
    const step = Math.max(1, Math.ceil(h.generation.length / 10));
    const layout = { grid: { rows: rows, columns: columns, pattern: "independent", xgap: 0.28, ygap: 0.42 },
                     showlegend: false, height: height, margin: { t: 20, b: 50, l: 80, r: 20 } };
    const traces = panels.map(([y, name, unit], k) => {
      const id = k ? String(k + 1) : "";
      layout["xaxis" + id] = { title: { text: "generation [1]" }, dtick: step, tick0: 0, automargin: true };
      layout["yaxis" + id] = Object.assign({ title: Object.assign(axisTitle(name, unit), { standoff: 8 }),
                                             exponentformat: "power", automargin: true },
                                           name === "feasible share" ? { range: [-0.05, 1.05] } : flat(y));
      return { type: "scatter", mode: "lines+markers", name: name, x: h.generation, y: y,
               xaxis: "x" + id, yaxis: "y" + id };
    });
    div.style.height = height + "px";
    return Plotly.newPlot(div, traces, layout, { displaylogo: false });
  }

  // Offsets [px] of a label's centre from its point: [sideways in half widths, down]; then
  // stacked further above and below.
  const CANDIDATES = [[0, -24], [0, 24], [1, 0], [-1, 0], [1, -26], [-1, -26], [1, 26], [-1, 26]];
  for (let n = 1; n <= 16; n++) CANDIDATES.push([0, -24 - 20 * n], [0, 24 + 20 * n]);
  function meets(a, b, gap) {
    return a.left < b.right + gap && b.left < a.right + gap && a.top < b.bottom + gap && b.top < a.bottom + gap;
  }
  function within(area, b) { return b.left >= area.left && b.right <= area.right && b.top >= area.top && b.bottom <= area.bottom; }
  function boxes(div) {  // the labels' boxes on screen by annotation index (none where hidden)
    const out = [];
    div.querySelectorAll(".annotation").forEach(a => {
      const t = a.querySelector(".annotation-text-g");
      if (t) out[Number(a.getAttribute("data-index"))] = t.getBoundingClientRect();
    });
    return out;
  }
  function offsets(div, labels) {
    const fl = div._fullLayout, xa = fl.xaxis, ya = fl.yaxis, sizes = boxes(div);
    const svg = div.querySelector(".main-svg").getBoundingClientRect();
    const area = { left: svg.left + xa._offset, right: svg.left + xa._offset + xa._length,
                   top: svg.top + ya._offset, bottom: svg.top + ya._offset + ya._length };
    const at = labels.map(l => [svg.left + xa._offset + xa.c2p(l.x), svg.top + ya._offset + ya.c2p(l.y)]);
    const points = at.map(([x, y]) => ({ left: x - 7, right: x + 7, top: y - 7, bottom: y + 7 }));
    const placed = [];
    return at.map(([x, y], k) => {
      const s = sizes[k];
      if (!s) return null;
      let chosen = null;
      for (const [side, dy] of CANDIDATES) {
        const dx = side * (s.width / 2 + 12);
        const box = { left: x + dx - s.width / 2, right: x + dx + s.width / 2,
                      top: y + dy - s.height / 2, bottom: y + dy + s.height / 2 };
        if (placed.some(b => meets(b, box, GAP)) || points.some(b => meets(b, box, 0))) continue;
        if (!chosen) chosen = [dx, dy, box];
        if (within(area, box)) { chosen = [dx, dy, box]; break; }
      }
      if (!chosen) return null;
      placed.push(chosen[2]);
      return chosen.slice(0, 2);
    });
  }
  function overlapping(div) {
    const b = boxes(div).filter(Boolean);
    return b.some((x, k) => b.slice(k + 1).some(y => meets(x, y, 0)));
  }
  function place(div, labels, pass) {
    const update = {};
    offsets(div, labels).forEach((o, k) => {
      if (o) { update["annotations[" + k + "].ax"] = o[0]; update["annotations[" + k + "].ay"] = o[1]; }
    });
    div._suspoptPlacing = true;
    return Plotly.relayout(div, update).then(() => {
      div._suspoptPlacing = false;
      if (pass < 4 && overlapping(div)) return place(div, labels, pass + 1);
      div.setAttribute("data-labelled", "1");
      return div;
    });
  }
  function placeLabels(div, labels) {
    const annotations = labels.map(l => ({ x: l.x, y: l.y, xref: "x", yref: "y", text: l.text,
      showarrow: true, arrowhead: 0, arrowwidth: 1, arrowcolor: "#999", ax: 0, ay: -24,
      font: { size: 12, color: l.color || "#333" }, bgcolor: "rgba(255,255,255,0.75)" }));
    div._suspoptLabels = labels;
    if (!div._suspoptWatch) {  // (again after a zoom or pan: the points moved)
      div._suspoptWatch = true;
      div.on("plotly_relayout", ev => {
        if (!div._suspoptPlacing && div._suspoptLabels.length &&
            Object.keys(ev).some(k => /^[xy]axis\.(range|autorange)/.test(k))) place(div, div._suspoptLabels, 0);
      });
    }
    div._suspoptPlacing = true;
    return Plotly.relayout(div, { annotations: annotations }).then(() => {
      div._suspoptPlacing = false;
      if (labels.length) return place(div, labels, 0);
      div.setAttribute("data-labelled", "1");
      return div;
    });
  }

  window.suspoptCharts = { distinct: distinct, lines: lines, history: history, placeLabels: placeLabels };
})();
