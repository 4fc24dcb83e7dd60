(function () {
  "use strict";
  const data = JSON.parse(document.getElementById("suspopt-data").textContent);
  const charts = window.suspoptCharts;  // (suspopt.report.charts)
  const api = { studies: [], selected: null, select: null };
  window.suspoptReport = api;

  function el(tag, text, parent) {
    const e = document.createElement(tag);
    if (text !== undefined && text !== null) e.textContent = String(text);
    if (parent) parent.appendChild(e);
    return e;
  }
  function fmt(v) { return v === null ? "-" : Number(v).toPrecision(5); }
  // a column by key: "F:j" objective j, "B:j" its value as built (kesort --as-built), "X:j" variable j
  function column(study, key) {
    const d = study.data, [kind, j] = key.split(":");
    const rows = kind === "F" ? d.F : kind === "B" ? d.F_as_built : d.X;
    return rows.map(r => r[Number(j)]);
  }
  function name(study, key) {
    const d = study.data, [kind, j] = key.split(":");
    if (kind === "B") return d.objectives[j] + ", as built (p" + d.as_built + ")";
    return kind === "F" ? d.objectives[j] : d.variables[j];
  }
  function label(study, key) {
    const d = study.data, [kind, j] = key.split(":");
    return name(study, key) + " [" + (kind === "X" ? d.variable_units[j] : d.objective_units[j]) + "]";
  }
  function select(el_, options, value) {
    for (const [k, text] of options) {
      const o = el("option", text, el_); o.value = k; if (k === value) o.selected = true;
    }
  }

  function designId(d, row) { return d.ids ? d.ids[row] : String(row); }  // (suspopt.design_ids)
  function showDesign(i, row) {
    const study = data.studies[i], d = study.data, box = document.getElementById("design-" + i);
    if (row === "config") return showBaseline(i, d, box);
    box.textContent = "";
    const id = designId(d, row);
    el("h3", "design " + id, box);
    const picks = Object.entries(d.picks).filter(([, r]) => r === row).map(([n]) => n);
    if (picks.length) el("div", "pick: " + picks.join(", "), box);
    const t = el("table", null, box);
    function add(name, value, unit, note) {
      const tr = el("tr", null, t); el("td", name, tr); el("td", fmt(value), tr); el("td", unit, tr);
      if (note) el("td", note, tr).className = "note";
    }
    const side = { "-": "at lower bound", "+": "at upper bound" };
    d.objectives.forEach((n, j) => {
      add(n, d.F[row][j], d.objective_units[j]);
      if (d.F_as_built) add(n + ", as built (p" + d.as_built + ")", d.F_as_built[row][j], d.objective_units[j]);
    });
    if (d.builds) showBuilds(d, row, t, box);
    d.variables.forEach((n, j) => add(n, d.X[row][j], d.variable_units[j],
                                      d.at_bound && side[d.at_bound[j][row]]));
    if (d.G) d.constraints.forEach((n, j) => add("g: " + n, d.G[row][j], d.constraint_units[j]));
    if (d.k_eps) add("k-ε level", d.k_eps[row], "1");
    if (d.case) add("case " + d.case[row], null, "");
    const onward = el("div", null, box);  // (paths as given to suspopt report)
    onward.className = "onward";
    el("div", "take it on (from where the report was made):", onward);
    const file = "design_" + id.replace(/[^A-Za-z0-9_.-]/g, "_");
    el("code", "suspopt export " + d.source + " --pick " + id + " -o " + file + ".yaml", onward);
    el("code", "suspopt simulate " + d.source + " --pick " + id + " -o " + file + ".h5 --plot " + file + ".png", onward);
    el("code", "suspopt analyse builds " + d.source + " --pick " + id + " -o " + file + "_builds.h5", onward);
    api.selected = { study: i, row: row };
    box.setAttribute("data-row", String(row));
  }
  api.select = showDesign;
  function showBuilds(d, row, t, box) {  // an analyse builds file: the spread of its builds
    const b = d.builds;
    d.objectives.forEach((n, j) => {
      const tr = el("tr", null, t); el("td", n + ", built 5-95 %", tr);
      el("td", fmt(b.low[row][j]) + " to " + fmt(b.high[row][j]), tr); el("td", d.objective_units[j], tr);
      const seen = new Set();  // (a batch's variables are drawn as one: one driver)
      const r2 = d.variables.map((v, i) => [b.batch[i] || v, b.contribution[row][i][j]])
        .filter(([v, c]) => c !== null && !seen.has(v) && seen.add(v))
        .sort((a, c) => c[1] - a[1]).map(([v, c]) => v + " " + c.toFixed(2)).join(", ");
      if (b.samples >= b.driver_samples && r2) el("td", "spread from: " + r2, tr).className = "note";
    });
    const tr = el("tr", null, t); el("td", "feasible builds", tr);
    el("td", fmt(100 * b.share[row]), tr); el("td", "%", tr);
    const one = b.tolerance.every(t => t === b.tolerance[0]);
    const within = one ? "every variable within ±" + b.tolerance[0] + " % of its value"
      : "each variable within its tolerance (" + d.variables.map((v, i) => v + " ±" + b.tolerance[i] + " %").join(", ") + ")";
    const batches = [...new Set(b.batch.filter(x => x))].map(x => d.variables.filter((v, i) => b.batch[i] === x).join(" and "));
    const alike = batches.length ? "; the parts of one batch off alike (" + batches.join("; ") + ")" : "";
    el("div", b.samples + " builds, " + within + " (" + b.distribution + ")" + alike, box).className = "note";
  }
  function showBaseline(i, d, box) {  // the config's own design (an optimise file's /baseline)
    box.textContent = "";
    el("h3", "the config's design", box);
    el("div", "the design the run started from: its config's own values", box).className = "note";
    const t = el("table", null, box), b = d.baseline;
    function add(name, value, unit) {
      const tr = el("tr", null, t); el("td", name, tr); el("td", fmt(value), tr); el("td", unit, tr);
    }
    d.objectives.forEach((n, j) => add(n, b.F[j], d.objective_units[j]));
    d.variables.forEach((n, j) => add(n, b.X[j], d.variable_units[j]));
    if (b.G) d.constraints.forEach((n, j) => add("g: " + n, b.G[j], d.constraint_units[j]));
    api.selected = { study: i, row: "config" };
    box.setAttribute("data-row", "config");
  }

  function colours(study) {
    const d = study.data, out = [];
    if (d.feasible) out.push(["feasible", "feasibility"]);
    if (d.k_eps) out.push(["k_eps", "k-ε level"]);
    if (d.case) out.push(["case", "case"]);
    d.objectives.forEach((n, j) => out.push(["F:" + j, n]));
    d.variables.forEach((n, j) => out.push(["X:" + j, n]));
    return out;
  }
  function colourValues(study, key) {
    const d = study.data;
    if (key === "feasible") return d.feasible.map(v => (v ? 1 : 0));
    if (key === "k_eps") return d.k_eps;
    if (key === "case") { const u = [...new Set(d.case)]; return d.case.map(c => u.indexOf(c)); }
    return column(study, key);
  }

  // the colour of the designs (the front's markers and the parallel coordinates' lines)
  function colouring(study, c) {
    const named = /^[FX]:/.test(c) ? label(study, c) : (colours(study).find(o => o[0] === c) || [c, c])[1];
    const out = { color: colourValues(study, c), colorscale: "Viridis",
                  colorbar: { title: { text: named }, exponentformat: "power" } };
    if (c === "feasible") Object.assign(out, { colorscale: [[0, "#d62728"], [1, "#1f77b4"]], cmin: 0, cmax: 1,
      colorbar: { title: { text: "feasible" }, tickvals: [0, 1], ticktext: ["no", "yes"] } });
    return out;
  }

  // Brushing: the ranges dragged along the parallel coordinates' axes (kept while a plot is
  // freed), and the rows inside all of them, which the front shows as selected.
  const brushes = data.studies.map(() => []);
  function inside(value, range) {  // (a value not finite, null in the data, is in no range)
    return value !== null && (Array.isArray(range[0]) ? range : [range]).some(r => value >= r[0] && value <= r[1]);
  }
  function brushed(i) {
    const study = data.studies[i], keys = parallelKeys(study);
    const active = keys.map((k, j) => [k, brushes[i][j]]).filter(([, r]) => r && r.length);
    if (!active.length) return null;
    const values = active.map(([k, r]) => [column(study, k), r]);
    return study.data.F.map((_, row) => row).filter(row => values.every(([v, r]) => inside(v[row], r)));
  }
  const BRUSH_COMMAND_ROWS = data.brush_command_rows;  // (suspopt.report.page.BRUSH_COMMAND_ROWS)
  function showBrush(i) {
    const rows = brushed(i), note = document.getElementById("brush-" + i);
    const box = document.getElementById("brush-command-" + i);
    note.textContent = rows ? rows.length + " of " + data.studies[i].data.rows + " designs in the brushed ranges" : "";
    box.textContent = "";
    if (!rows || !rows.length) return;
    if (rows.length > BRUSH_COMMAND_ROWS) {
      el("div", "(more than " + BRUSH_COMMAND_ROWS + " designs: narrow the ranges to simulate them in one command)", box);
      return;
    }
    el("div", "simulate them in one batch (from where the report was made):", box);
    el("code", "suspopt simulate " + data.studies[i].data.source + " --pick " + rows.map(r => designId(data.studies[i].data, r)).join(",") + " -o brushed.h5", box);
  }

  function baselineTrace(d, x, y) {  // the config's own design: where the run started
    const at = key => { const [kind, j] = key.split(":"); return (kind === "F" ? d.baseline.F : d.baseline.X)[Number(j)]; };
    return { type: "scatter", mode: "markers", name: "the config's design", x: [at(x)], y: [at(y)],
             text: ["config"], hoverinfo: "text+x+y", customdata: ["config"],
             marker: { symbol: "diamond-open", size: 12, color: "#000", line: { width: 2 } } };
  }
  function drawFront(i) {
    const study = data.studies[i], d = study.data;
    const x = document.getElementById("x-" + i).value, y = document.getElementById("y-" + i).value;
    const c = document.getElementById("c-" + i).value;
    const three = document.getElementById("d3-" + i);
    const rows = d.F.map((_, r) => r);
    const hover = rows.map(r => "design " + designId(d, r) + "<br>" + d.objectives.map((n, j) => n + " " + fmt(d.F[r][j])).join("<br>"));
    const marker = Object.assign(colouring(study, c), { showscale: true, size: 7 });
    const traces = [], labels = [];
    const use3d = three && three.checked;
    const chosen = brushed(i);
    if (use3d) {  // (scatter3d has no selected points: the brushed rows and the rest as two traces)
      const split = chosen ? [chosen, rows.filter(r => !chosen.includes(r))] : [rows, []];
      const pick = (values, subset) => subset.map(r => values[r]);
      const xyz = subset => ({ x: pick(column(study, "F:0"), subset), y: pick(column(study, "F:1"), subset),
                               z: pick(column(study, "F:2"), subset), customdata: subset,
                               text: pick(hover, subset), hoverinfo: "text" });
      const finite = marker.color.filter(v => v !== null);  // (the colour scale of every design)
      const range = marker.cmin === undefined && finite.length
        ? { cmin: finite.reduce((a, b) => Math.min(a, b)), cmax: finite.reduce((a, b) => Math.max(a, b)) } : {};
      traces.push(Object.assign({ type: "scatter3d", mode: "markers", name: "designs" }, xyz(split[0]),
        { marker: Object.assign({}, marker, range, { size: 4, color: pick(marker.color, split[0]) }) }));
      if (split[1].length) traces.push(Object.assign({ type: "scatter3d", mode: "markers",
        name: "outside the brushed ranges" }, xyz(split[1]), { marker: { size: 3, color: "#bbb", opacity: 0.3 } }));
      if (d.baseline) traces.push(Object.assign(baselineTrace(d, "F:0", "F:1"),
        { type: "scatter3d", z: [d.baseline.F[2]], marker: { symbol: "diamond-open", size: 6, color: "#000" } }));
    } else {
      traces.push({ type: "scatter",
        mode: "markers", name: "designs", x: column(study, x), y: column(study, y), customdata: rows,
        text: hover, hoverinfo: "text", marker: marker, selectedpoints: chosen,
        unselected: { marker: { opacity: 0.15 } } });
      const names = Object.keys(d.picks), pr = names.map(n => d.picks[n]);
      const marked = pickLabels(pr.map(r => column(study, x)[r]), pr.map(r => column(study, y)[r]), names, pr);
      traces.push({ type: "scatter", mode: "markers", name: "picks", x: marked.map(l => l.x),
        y: marked.map(l => l.y), text: marked.map(l => l.text), customdata: marked.map(l => l.row),
        hoverinfo: "text", marker: { symbol: "x", size: 12, color: "#d62728" } });
      labels.push(...marked);
      if (d.baseline) {
        traces.push(baselineTrace(d, x, y));
        labels.push({ x: traces[traces.length - 1].x[0], y: traces[traces.length - 1].y[0], text: "config" });
      }
      for (const p of d.pseudo || []) {
        if (!x.startsWith("F:") || !y.startsWith("F:")) break;
        const jx = Number(x.slice(2)), jy = Number(y.slice(2)), lx = [], ly = [];
        p.F.forEach((r, k) => { lx.push(d.F[k][jx], r[jx], null); ly.push(d.F[k][jy], r[jy], null); });
        traces.push({ type: "scatter", mode: "markers", name: p.label, x: p.F.map(r => r[jx]),
          y: p.F.map(r => r[jy]), customdata: rows, marker: { size: 6, symbol: "diamond" } });
        traces.push({ type: "scatter", mode: "lines", name: p.label + " (moves)", x: lx, y: ly,
          hoverinfo: "skip", line: { width: 0.8, color: "#999" } });
      }
    }
    const layout = use3d ? { scene: { xaxis: { title: { text: label(study, "F:0") } },
                                      yaxis: { title: { text: label(study, "F:1") } },
                                      zaxis: { title: { text: label(study, "F:2") } } },
                             margin: { t: 20 }, legend: { orientation: "h", y: -0.05 } }
                         : { xaxis: { title: { text: label(study, x) }, exponentformat: "power" },
                             yaxis: { title: { text: label(study, y) }, exponentformat: "power" },
                             margin: { t: 20 }, legend: { orientation: "h", y: -0.18 } };
    const div = document.getElementById("front-" + i);
    return Plotly.react(div, traces, layout, { displaylogo: false })
      .then(() => (use3d ? div : charts.placeLabels(div, labels)));
  }
  function pickLabels(xs, ys, names, rows) {  // one per point of the picks, naming the picks there
    const at = new Map();
    xs.forEach((x, k) => {
      const y = ys[k], key = x + " " + y;
      if (x === null || y === null) return;
      if (!at.has(key)) at.set(key, { x: x, y: y, names: [], row: rows[k], color: "#d62728" });
      at.get(key).names.push(names[k]);
    });
    return [...at.values()].map(l => Object.assign(l, { text: l.names.join(", ") }));
  }

  // Parallel coordinates are WebGL plots of three contexts each, and a browser keeps about 16
  // per page, losing the oldest beyond (Chromium: "Too many active WebGL contexts"). So each is
  // drawn when it comes on screen (or its button is pressed), and when PARALLEL_LIVE are drawn
  // the one drawn longest ago that is off screen is freed (its contexts lost on purpose) and
  // drawn again when it comes back. It draws at the screen's pixel ratio (plotly's default, 2,
  // draws four times the pixels on an ordinary screen).
  const PARALLEL_LIVE = 3, parallelLive = [], parallelSeen = new Set();
  function parallelButton(i) {
    const div = document.getElementById("parallel-" + i);
    div.textContent = "";
    el("button", "draw the parallel coordinates", div).addEventListener("click", () => drawParallel(i));
  }
  function freeParallel(i) {
    const div = document.getElementById("parallel-" + i);
    div.querySelectorAll("canvas.gl-canvas").forEach(c => {
      const gl = c.getContext("webgl") || c.getContext("experimental-webgl");
      const lose = gl && gl.getExtension("WEBGL_lose_context");
      if (lose) lose.loseContext();
    });
    Plotly.purge(div);
    div.removeAttribute("data-drawn");
    parallelButton(i);
  }
  function drawParallel(i) {
    if (parallelLive.includes(i)) return Promise.resolve();
    while (parallelLive.length >= PARALLEL_LIVE) {
      const k = parallelLive.findIndex(j => !parallelSeen.has(j));
      freeParallel(parallelLive.splice(k < 0 ? 0 : k, 1)[0]);
    }
    parallelLive.push(i);
    const div = document.getElementById("parallel-" + i);
    div.textContent = "";
    return plotParallel(i)
      .then(() => {
        if (!parallelLive.includes(i)) return;
        div.setAttribute("data-drawn", "1");
        div.on("plotly_restyle", () => {
          brushes[i] = div.data[0].dimensions.map(d => d.constraintrange || null);
          showBrush(i);
          drawFront(i);
        });
      });
  }
  function plotParallel(i) {  // (the first drawing, and a new colour)
    return Plotly.react("parallel-" + i, parallelTraces(i), { margin: { t: 40 } },
      { displaylogo: false, plotGlPixelRatio: Math.min(2, Math.max(1, window.devicePixelRatio || 1)) });
  }
  function parallelKeys(study) {
    const d = study.data;
    return d.objectives.map((_, j) => "F:" + j).concat(d.variables.map((_, j) => "X:" + j));
  }
  function parallelTraces(i) {
    const study = data.studies[i], keys = parallelKeys(study);
    const dims = keys.map((k, j) => Object.assign({ label: name(study, k), values: column(study, k) },
                                                  searchRange(study, k),
                                                  brushes[i][j] ? { constraintrange: brushes[i][j] } : {}));
    const line = colouring(study, document.getElementById("c-" + i).value);
    delete line.colorbar;
    return [{ type: "parcoords", dimensions: dims, line: line }];
  }
  function searchRange(study, key) {  // a variable's axis spans its bounds (and its values)
    const d = study.data, [kind, j] = key.split(":"), b = d.variable_bounds;
    if (kind !== "X" || !b || b[0][j] === null || b[1][j] === null) return {};
    const v = column(study, key).filter(x => x !== null);
    return { range: [v.reduce((a, x) => Math.min(a, x), b[0][j]), v.reduce((a, x) => Math.max(a, x), b[1][j])] };
  }
  const parallelWatch = "IntersectionObserver" in window ? new IntersectionObserver(entries => {
    for (const e of entries) {
      const i = Number(e.target.id.slice("parallel-".length));
      if (e.isIntersecting) { parallelSeen.add(i); drawParallel(i); } else parallelSeen.delete(i);
    }
  }, { rootMargin: "200px" }) : null;

  function drawHistory(i) {
    const h = data.studies[i].data.history;
    return h ? charts.history(document.getElementById("history-" + i), h) : Promise.resolve();
  }

  function drawSignals(i) {
    const d = data.studies[i].data, s = d.signals;
    const names = Object.keys(s.signals);
    if (!names.length) return Promise.resolve();
    const pick = document.getElementById("s-" + i).value;
    const labels = s.rows.map(row => "design " + designId(d, row));
    const traces = charts.lines(s.time, s.signals[pick], labels, "");
    const spectra = charts.lines(s.psd_f, s.psd[pick], labels, "");
    const unit = s.units[pick], range = s.psd_range[pick], below = { orientation: "h", y: -0.2 };
    const f = [s.psd_f[0], s.psd_f[s.psd_f.length - 1]].map(Math.log10);
    return Promise.all([
      Plotly.react("signal-" + i, traces, { xaxis: { title: { text: "time [s]" } },
        yaxis: { title: { text: pick + " [" + unit + "]" }, exponentformat: "power" }, margin: { t: 20 }, legend: below },
        { displaylogo: false }),
      Plotly.react("psd-" + i, spectra, { xaxis: { title: { text: "frequency [Hz]" }, type: "log", range: f },
        yaxis: Object.assign({ title: { text: "PSD of " + pick + " [" + s.psd_units[pick] + "]" }, type: "log",
                               exponentformat: "power" }, range ? { range: range.map(Math.log10) } : {}),
        margin: { t: 20 }, legend: below }, { displaylogo: false }),
    ]);
  }

  function drawTransmissibility(i) {
    const d = data.studies[i].data, t = d.signals.transmissibility;
    if (!t) return Promise.resolve();
    const traces = [];
    for (const [dof, curves] of Object.entries(t.dofs)) {
      traces.push(...charts.lines(t.f, curves, t.rows.map(row => "design " + designId(d, row)),
        (dof === "head" ? "STHT (head)" : dof) + ", ", { line: { dash: dof === "head" ? "solid" : "dot" } }));
    }
    return Plotly.newPlot("tr-" + i, traces, { xaxis: { title: { text: "frequency [Hz]" }, type: "log" },
      yaxis: { title: { text: "|transmissibility| [1]" }, type: "log" }, margin: { t: 20 },
      legend: { orientation: "h", y: -0.2 } }, { displaylogo: false });
  }

  const done = [];
  data.studies.forEach((study, i) => {
    const d = study.data, keys = d.objectives.map((n, j) => ["F:" + j, n])
      .concat(d.F_as_built ? d.objectives.map((n, j) => ["B:" + j, name(study, "B:" + j)]) : [])
      .concat(d.variables.map((n, j) => ["X:" + j, n]));
    const xs = document.getElementById("x-" + i), ys = document.getElementById("y-" + i);
    select(xs, keys, d.objectives.length > 1 ? "F:0" : "X:0");
    select(ys, keys, d.objectives.length > 1 ? "F:1" : "F:0");
    const mixed = d.feasible && d.feasible.some(v => !v);
    select(document.getElementById("c-" + i), colours(study),
           mixed ? "feasible" : d.k_eps ? "k_eps" : d.variables.length ? "X:0" : "F:0");
    const sig = document.getElementById("s-" + i);
    if (sig) select(sig, Object.keys(d.signals.signals).map(n => [n, n]), Object.keys(d.signals.signals)[0]);
    const front = drawFront(i).then(div => {
      div.on("plotly_click", ev => { const p = ev.points[0]; if (p && p.customdata !== undefined) showDesign(i, p.customdata); });
    });
    for (const id of ["x-", "y-", "c-", "d3-"]) {
      const e = document.getElementById(id + i); if (e) e.addEventListener("change", () => drawFront(i));
    }
    document.getElementById("c-" + i).addEventListener("change", () => {
      if (parallelLive.includes(i)) plotParallel(i);
    });
    if (sig) sig.addEventListener("change", () => drawSignals(i));
    api.studies.push({ label: study.label, points: d.rows, front: "front-" + i, parallel: "parallel-" + i });
    parallelButton(i);
    done.push(front, drawHistory(i), drawSignals(i), drawTransmissibility(i));
    showDesign(i, Object.values(d.picks)[0] || 0);
  });
  Promise.all(done).then(() => {
    document.body.setAttribute("data-rendered", "1");
    // (the parallel coordinates after the rest: the front shows first)
    if (parallelWatch) data.studies.forEach((_, i) => parallelWatch.observe(document.getElementById("parallel-" + i)));
  });
})();
