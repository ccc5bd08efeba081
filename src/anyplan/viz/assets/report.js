/* anyplan report: sortable tables, drill-down to runs, SVG plots with hover, trajectory playback.
   Reads the JSON in <script id="report-data">; uses no external resource. */
(function () {
  "use strict";
  var D = JSON.parse(document.getElementById("report-data").textContent);
  var PALETTE = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"];
  var tip = document.createElement("div");
  tip.className = "tip";
  document.body.appendChild(tip);

  function showTip(ev, text) {
    tip.textContent = text;
    tip.style.display = "block";
    tip.style.left = (ev.clientX + 12) + "px";
    tip.style.top = (ev.clientY + 12) + "px";
  }
  function hideTip() { tip.style.display = "none"; }

  /* ---------------------------------------------------------------- sortable tables */
  function cellValue(td) {
    var v = td.getAttribute("data-v");
    if (v !== null && v !== "") return parseFloat(v);
    var t = td.textContent.trim();
    var f = parseFloat(t);
    return (!isNaN(f) && /^[-+0-9.]/.test(t)) ? f : t.toLowerCase();
  }
  function sortTable(table, col, th) {
    var asc = th.getAttribute("aria-sort") !== "ascending";
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (c) { c.removeAttribute("aria-sort"); });
    th.setAttribute("aria-sort", asc ? "ascending" : "descending");
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = cellValue(a.cells[col]), y = cellValue(b.cells[col]);
      var nx = typeof x === "number", ny = typeof y === "number";
      var r = (nx && ny) ? x - y : (nx ? -1 : (ny ? 1 : (x < y ? -1 : (x > y ? 1 : 0))));
      return asc ? r : -r;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  }
  Array.prototype.forEach.call(document.querySelectorAll("table.sortable"), function (table) {
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th, i) {
      th.title = "sort by " + th.textContent;
      th.addEventListener("click", function () { sortTable(table, i, th); });
    });
  });

  /* ---------------------------------------------------------------- drill-down to runs */
  var runsTable = document.getElementById("runs-table");
  var filterBox = document.getElementById("runs-filter");
  function showRuns(ids, what) {
    var keep = {};
    if (ids !== null) ids.forEach(function (id) { keep[String(id)] = true; });
    var shown = 0;
    Array.prototype.forEach.call(runsTable.tBodies[0].rows, function (tr) {
      var on = ids === null || keep[tr.getAttribute("data-id")];
      tr.classList.toggle("hidden", !on);
      if (on) shown += 1;
    });
    if (ids === null) {
      filterBox.innerHTML = "All " + shown + " runs.";
    } else {
      filterBox.innerHTML = "";
      var s = document.createElement("span");
      s.className = "filter";
      s.textContent = shown + " run(s) behind " + what + " ";
      var b = document.createElement("button");
      b.id = "runs-all";
      b.textContent = "show all runs";
      b.addEventListener("click", function () { showRuns(null, ""); });
      s.appendChild(b);
      filterBox.appendChild(s);
    }
  }
  function drill(ids, what) {
    showRuns(ids, what);
    location.hash = "#runs";
    document.getElementById("runs").scrollIntoView();
  }
  document.addEventListener("click", function (ev) {
    var a = ev.target.closest("a.drill");
    if (a) {
      ev.preventDefault();
      var raw = a.getAttribute("data-runs").trim();
      drill(raw ? raw.split(" ") : [], a.getAttribute("data-what"));
      return;
    }
    var p = ev.target.closest("button.play");
    if (p) {
      ev.preventDefault();
      loadRun(p.getAttribute("data-run"), true);
    }
  });
  if (runsTable) showRuns(null, "");

  /* ---------------------------------------------------------------- SVG plots */
  var NS = "http://www.w3.org/2000/svg";
  function el(name, attrs, parent) {
    var e = document.createElementNS(NS, name);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function ticks(lo, hi, n) {
    var span = hi - lo || 1, step = Math.pow(10, Math.floor(Math.log10(span / n)));
    [1, 2, 5, 10].some(function (m) { if (span / (m * step) <= n) { step *= m; return true; } return false; });
    var out = [];
    for (var v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) out.push(+v.toPrecision(10));
    return out;
  }
  function chart(box, s) {
    var W = 360, H = 250, L = 52, R = 10, T = 10, B = 40;
    var pts = [];
    s.lines.forEach(function (l) { l.points.forEach(function (p) { pts.push(p); }); });
    if (!pts.length) { box.appendChild(document.createTextNode("no data")); return; }
    var xs = pts.map(function (p) { return p.x; });
    var lo = Math.min.apply(null, pts.map(function (p) { return p.y - (p.sd || 0); }));
    var hi = Math.max.apply(null, pts.map(function (p) { return p.y + (p.sd || 0); }));
    if (hi - lo < 1e-12) { lo -= 1; hi += 1; }
    var pad = 0.08 * (hi - lo); lo -= pad; hi += pad;
    var x0 = Math.min.apply(null, xs) - 0.5, x1 = Math.max.apply(null, xs) + 0.5;
    var sx = function (x) { return L + (x - x0) / (x1 - x0) * (W - L - R); };
    var sy = function (y) { return T + (hi - y) / (hi - lo) * (H - T - B); };
    var svg = el("svg", {viewBox: "0 0 " + W + " " + H, role: "img", "aria-label": s.label}, box);
    el("rect", {x: L, y: T, width: W - L - R, height: H - T - B, fill: "none", stroke: "#888"}, svg);
    ticks(lo, hi, 5).forEach(function (v) {
      el("line", {x1: L, x2: W - R, y1: sy(v), y2: sy(v), stroke: "#e3e3e3"}, svg);
      el("text", {x: L - 4, y: sy(v) + 4, "text-anchor": "end", "font-size": 11}, svg).textContent = v;
    });
    var xv = {};
    xs.forEach(function (x) { xv[x] = 1; });
    Object.keys(xv).forEach(function (x) {
      el("text", {x: sx(+x), y: H - B + 15, "text-anchor": "middle", "font-size": 11}, svg).textContent = x;
    });
    el("text", {x: (L + W - R) / 2, y: H - 6, "text-anchor": "middle", "font-size": 11}, svg).textContent =
      "moving obstacles";
    el("text", {x: 12, y: (T + H - B) / 2, "text-anchor": "middle", "font-size": 11,
      transform: "rotate(-90 12 " + (T + H - B) / 2 + ")"}, svg).textContent = s.label;
    var nl = s.lines.length;
    s.lines.forEach(function (l, k) {
      var c = PALETTE[k % PALETTE.length], off = (k - (nl - 1) / 2) * 0.08;
      var d = l.points.map(function (p, i) { return (i ? "L" : "M") + sx(p.x + off) + " " + sy(p.y); }).join(" ");
      if (d) el("path", {d: d, fill: "none", stroke: c, "stroke-width": 1.5}, svg);
      l.points.forEach(function (p) {
        var x = sx(p.x + off);
        if (p.sd !== null && p.sd !== undefined) {
          el("line", {x1: x, x2: x, y1: sy(p.y - p.sd), y2: sy(p.y + p.sd), stroke: c}, svg);
        }
        var dot = el("circle", {cx: x, cy: sy(p.y), r: 5, fill: c, stroke: "#fff", "class": "pt"}, svg);
        var txt = l.name + ", " + p.x + " moving obstacles\n" + s.label + ": " + p.y.toPrecision(4) +
          (p.sd !== null && p.sd !== undefined ? " ± " + p.sd.toPrecision(3) : "") + " (n = " + p.n + ")\nclick: the runs";
        dot.addEventListener("mousemove", function (ev) { showTip(ev, txt); });
        dot.addEventListener("mouseleave", hideTip);
        dot.addEventListener("click", function () {
          hideTip();
          drill(p.runs.map(String), l.name + ", " + p.x + " moving obstacles, " + s.label + " (n = " + p.n + ")");
        });
      });
    });
    var lg = document.createElement("div");
    lg.className = "legend";
    s.lines.forEach(function (l, k) {
      var sp = document.createElement("span");
      sp.innerHTML = "<i class='sw' style='background:" + PALETTE[k % PALETTE.length] + "'></i>";
      sp.appendChild(document.createTextNode(l.name));
      lg.appendChild(sp);
    });
    box.appendChild(lg);
  }
  var plots = document.getElementById("plots-box");
  if (plots) {
    D.series.forEach(function (s) {
      var div = document.createElement("div");
      div.className = "plot";
      div.innerHTML = "<h3></h3>";
      div.firstChild.textContent = s.label + " (mean ± std; counted: " + s.counted + " runs)";
      plots.appendChild(div);
      chart(div, s);
    });
  }

  /* ---------------------------------------------------------------- playback */
  var cv = document.getElementById("pb-canvas");
  var ctx = cv ? cv.getContext("2d") : null;
  var slider = document.getElementById("pb-slider");
  var timeBox = document.getElementById("pb-time");
  var playBtn = document.getElementById("pb-play");
  var speedSel = document.getElementById("pb-speed");
  var PB = {run: null, track: null, scene: null, t: 0, playing: false, last: null};
  var MOVER = ["#d62728", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"];
  function moverColor(j) {
    if (j < MOVER.length) return MOVER[j];
    var h = ((0.07 + (j - MOVER.length) * 0.6180339887) % 1) * 360;
    return "hsl(" + h.toFixed(0) + ",70%," + [45, 35, 55][j % 3] + "%)";
  }
  function interp(ts, vs, t) {
    if (t <= ts[0]) return vs[0];
    var n = ts.length;
    if (t >= ts[n - 1]) return vs[n - 1];
    var lo = 0, hi = n - 1;
    while (hi - lo > 1) { var m = (lo + hi) >> 1; if (ts[m] <= t) lo = m; else hi = m; }
    var f = (t - ts[lo]) / (ts[hi] - ts[lo]);
    return vs[lo] + f * (vs[hi] - vs[lo]);
  }
  function draw() {
    var sc = PB.scene, tr = PB.track;
    if (!sc || !tr) return;
    var m = 14, k = Math.min((cv.width - 2 * m) / sc.width, (cv.height - 2 * m) / sc.height);
    var ox = sc.x0 || 0, oy = sc.y0 || 0;  // the arena's lower-left corner [m]
    var X = function (x) { return m + (x - ox) * k; }, Y = function (y) { return cv.height - m - (y - oy) * k; };
    ctx.clearRect(0, 0, cv.width, cv.height);
    ctx.lineWidth = 2; ctx.strokeStyle = "#000"; ctx.strokeRect(X(ox), Y(oy + sc.height), sc.width * k, sc.height * k);
    ctx.font = "12px sans-serif"; ctx.textAlign = "center"; ctx.textBaseline = "middle";
    sc.statics.forEach(function (o) {
      ctx.fillStyle = "#b0b0b0"; ctx.strokeStyle = "#424242"; ctx.lineWidth = 1;
      ctx.beginPath();
      var cx, cy;
      if (o.circle) { ctx.arc(X(o.circle[0]), Y(o.circle[1]), o.circle[2] * k, 0, 2 * Math.PI); cx = o.circle[0]; cy = o.circle[1]; }
      else {
        cx = 0; cy = 0;
        o.polygon.forEach(function (p, i) { if (i) ctx.lineTo(X(p[0]), Y(p[1])); else ctx.moveTo(X(p[0]), Y(p[1])); cx += p[0]; cy += p[1]; });
        cx /= o.polygon.length; cy /= o.polygon.length; ctx.closePath();
      }
      ctx.fill(); ctx.stroke();
      ctx.fillStyle = "#1a1a1a"; ctx.fillText(o.name, X(cx), Y(cy));
    });
    var t = PB.t;
    ctx.fillStyle = "rgba(44,160,44,0.3)";
    ctx.beginPath(); ctx.arc(X(sc.goal[0]), Y(sc.goal[1]), Math.max(sc.goal_tolerance * k, 3), 0, 2 * Math.PI); ctx.fill();
    tr.virtual.forEach(function (v) {
      if (v[3] > t) return;
      ctx.fillStyle = "rgba(30,99,214,0.3)"; ctx.strokeStyle = "#1e63d6";
      ctx.fillRect(X(v[0] - v[2] / 2), Y(v[1] + v[2] / 2), v[2] * k, v[2] * k);
      ctx.strokeRect(X(v[0] - v[2] / 2), Y(v[1] + v[2] / 2), v[2] * k, v[2] * k);
    });
    sc.movers.forEach(function (o, j) {
      var span = o.span || [null, null];  // a recorded track exists only within its span
      if ((span[0] !== null && t < span[0]) || (span[1] !== null && t > span[1])) return;
      var x = interp(sc.t, sc.mover_xy[j][0], t), y = interp(sc.t, sc.mover_xy[j][1], t);
      ctx.fillStyle = moverColor(j); ctx.globalAlpha = 0.85;
      ctx.beginPath(); ctx.arc(X(x), Y(y), o.radius * k, 0, 2 * Math.PI); ctx.fill();
      ctx.globalAlpha = 1; ctx.fillStyle = "#1a1a1a"; ctx.fillText(o.name, X(x), Y(y) - o.radius * k - 7);
    });
    ctx.strokeStyle = "#1f77b4"; ctx.lineWidth = 2; ctx.beginPath();
    for (var i = 0; i < tr.t.length && tr.t[i] <= t; i++) {
      if (i) ctx.lineTo(X(tr.x[i]), Y(tr.y[i])); else ctx.moveTo(X(tr.x[i]), Y(tr.y[i]));
    }
    var rx = interp(tr.t, tr.x, t), ry = interp(tr.t, tr.y, t), rth = interp(tr.t, tr.th, t);
    ctx.lineTo(X(rx), Y(ry)); ctx.stroke();
    ctx.fillStyle = "#1f77b4"; ctx.strokeStyle = "#000"; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.arc(X(rx), Y(ry), sc.robot_radius * k, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    ctx.strokeStyle = "#fff"; ctx.lineWidth = 2; ctx.beginPath(); ctx.moveTo(X(rx), Y(ry));
    ctx.lineTo(X(rx + sc.robot_radius * Math.cos(rth)), Y(ry + sc.robot_radius * Math.sin(rth))); ctx.stroke();
    var tEnd = tr.t[tr.t.length - 1];
    if (tr.collision && t >= tEnd - 1e-9) {
      ctx.fillStyle = "#c00"; ctx.font = "bold 14px sans-serif";
      ctx.fillText("collision with " + tr.collision["with"], X(rx), Y(ry) - sc.robot_radius * k - 10);
    }
    timeBox.textContent = "t = " + t.toFixed(1) + " s of " + tEnd.toFixed(1) + " s" + (t >= tEnd - 1e-9 ? " (" + tr.status + ")" : "");
    slider.value = String(t);
  }
  function step(now) {
    if (!PB.playing) return;
    if (PB.last !== null) {
      var tEnd = PB.track.t[PB.track.t.length - 1];
      PB.t = Math.min(tEnd, PB.t + (now - PB.last) / 1000 * parseFloat(speedSel.value));
      if (PB.t >= tEnd) { PB.playing = false; playBtn.textContent = "play"; }
    }
    PB.last = now;
    draw();
    if (PB.playing) requestAnimationFrame(step);
  }
  function setPlaying(on) {
    PB.playing = on && !!PB.track;
    playBtn.textContent = PB.playing ? "pause" : "play";
    PB.last = null;
    if (PB.playing) {
      if (PB.t >= PB.track.t[PB.track.t.length - 1] - 1e-9) PB.t = 0;
      requestAnimationFrame(step);
    }
  }
  function loadRun(id, play) {
    var tr = D.tracks[String(id)];
    var run = D.runs.filter(function (r) { return String(r.id) === String(id); })[0];
    if (!tr || !run) return;
    PB.run = run; PB.track = tr; PB.scene = D.scenes[String(run.experimentid)]; PB.t = 0;
    var sc = PB.scene, w = Math.min(900, cv.parentNode.clientWidth || 900);
    cv.width = w; cv.height = Math.round(w * (sc.height + 0.25) / (sc.width + 0.25));
    slider.max = String(tr.t[tr.t.length - 1]); slider.step = String(D.meta.playback_dt_s / 4);
    document.getElementById("pb-title").textContent = "Run " + run.id + ": " + run.planner + " on " + run.scenario +
      ", run " + run.run_index + ", seed " + run.seed + ": " + run.outcome +
      (sc.static_map ? " (the scenario's occupancy map is not drawn here)" : "");
    Array.prototype.forEach.call(runsTable.tBodies[0].rows, function (r) {
      r.classList.toggle("selected", r.getAttribute("data-id") === String(id));
    });
    draw();
    if (play) {
      location.hash = "#playback";
      document.getElementById("playback").scrollIntoView();
      setPlaying(true);
    }
  }
  if (cv) {
    playBtn.addEventListener("click", function () { setPlaying(!PB.playing); });
    slider.addEventListener("input", function () { PB.t = parseFloat(slider.value); setPlaying(false); draw(); });
    var first = D.runs.filter(function (r) { return D.tracks[String(r.id)]; })[0];
    if (first) loadRun(first.id, false);
    window.anyplanPlayback = PB;
  }

  /* ---------------------------------------------------------------- table of contents */
  var links = document.querySelectorAll("#toc a");
  function mark() {
    var h = location.hash;
    Array.prototype.forEach.call(links, function (a) { a.classList.toggle("active", a.getAttribute("href") === h); });
  }
  window.addEventListener("hashchange", mark);
  mark();
})();
