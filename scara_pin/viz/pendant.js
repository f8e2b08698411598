// scara-pin's pendant: joint sliders, the tool pose readout, a motion player and (live) the teach pendant.
// Moves the robot through meshcat's scene tree: each joint is a node, whose transform is its placement
// times its own rotation about (or translation along) its axis; nothing else of the kinematics is here.
// The readout is read from three.js's world matrices (offline) or is the server's Pinocchio FK (teach).
// Everything the server gets and sends is SI (m, rad); this page converts to and from the units chosen.
(function () {
  "use strict";
  var THREE = MeshCat.THREE;
  var data = JSON.parse(document.getElementById("scara-data").textContent);
  var q = data.q.slice();
  var teach = data.teach || null;
  var sliders = [];
  var lastPose = null, lastQ = null, lastPoints = [];

  function node(path) { return viewer.scene_tree.find(path.split("/")); }
  function $(id) { return document.getElementById(id); }

  // --------------------------------------------------------------- units: display only, SI inside
  var DEG = Math.PI / 180;  // as Python's math.radians: v * (pi / 180)
  var units = data.units === "m" ? "m" : "mm";  // the units the page opens in (job --html: the command line's)
  function human() { return units === "mm"; }
  function lengthUnit() { return human() ? "mm" : "m"; }
  function angleUnit() { return human() ? "deg" : "rad"; }
  // SI -> the chosen unit, and back (mm: / 1000 so that 10 mm is the double nearest 0.01 m)
  function toUnit(v, kind) { return kind === "angle" ? (human() ? v / DEG : v) : (human() ? v * 1000 : v); }
  function fromUnit(v, kind) { return kind === "angle" ? (human() ? v * DEG : v) : (human() ? v / 1000 : v); }
  // decimals: 1 um and 0.001 deg (1e-6 rad)
  function decimals(kind) { return kind === "angle" ? (human() ? 3 : 6) : (human() ? 3 : 6); }
  // a value rounded to the readout's resolution; never "-0.000"
  function fmt(v, kind) {
    var d = decimals(kind), s = toUnit(v, kind).toFixed(d);
    if (Number(s) === 0) s = (0).toFixed(d);
    return s;
  }
  function unitOf(kind) { return kind === "angle" ? angleUnit() : lengthUnit(); }
  // in words: the readout's rounding, trailing zeros dropped ("132", "24.783"), and with its unit
  function number(v, kind) { return String(Number(fmt(v, kind))); }
  function amount(v, kind) { return number(v, kind) + " " + unitOf(kind); }
  var POSE_KINDS = ["length", "length", "length", "angle"];
  function jointKind(index) {
    for (var i = 0; i < data.sliders.length; i++) {
      if (data.sliders[i].index === index) return data.sliders[i].unit === "m" ? "length" : "angle";
    }
    return "angle";
  }

  function applyQ() {
    data.joints.forEach(function (j) {
      var value = j.multiplier * q[j.source] + j.offset;
      var m = new THREE.Matrix4();
      m.set.apply(m, j.placement);  // row-major
      var motion = new THREE.Matrix4();
      if (j.kind === "revolute") {
        motion.makeRotationAxis(new THREE.Vector3(j.axis[0], j.axis[1], j.axis[2]), value);
      } else {
        motion.makeTranslation(j.axis[0] * value, j.axis[1] * value, j.axis[2] * value);
      }
      m.multiply(motion);
      node(j.path).set_transform(m.toArray());
    });
    viewer.set_dirty();
  }

  // the tool frame in the base frame, from the scene graph: (x, y, z [m], yaw [rad])
  function scenePose() {
    viewer.scene.updateMatrixWorld(true);
    var base = node(data.base).object.matrixWorld, tool = node(data.tool).object.matrixWorld;
    var rel = new THREE.Matrix4().copy(base).invert().multiply(tool);
    var e = rel.elements;  // column-major
    return [e[12], e[13], e[14], Math.atan2(e[1], e[0])];
  }

  function showPose(pose) {
    lastPose = pose;
    var names = ["x", "y", "z", "yaw"], lines = [];
    for (var i = 0; i < 4; i++) lines.push(names[i] + " = " + fmt(pose[i], POSE_KINDS[i]) + " " + unitOf(POSE_KINDS[i]));
    $("tool-pose").textContent = lines.join("\n");
  }

  function showJoints(values) {
    lastQ = values;
    var box = $("joint-values");
    if (!box) return;
    box.textContent = data.sliders.map(function (s) {
      var kind = jointKind(s.index);
      return s.name + " = " + fmt(values[s.index], kind) + " " + unitOf(kind);
    }).join("\n");
  }

  function sliderText(s, value) {
    var kind = jointKind(s.index);
    return fmt(value, kind) + " " + unitOf(kind);
  }

  function syncSliders() {
    sliders.forEach(function (s) {
      s.input.value = String(q[s.index]);
      s.output.textContent = sliderText(s, q[s.index]);
    });
  }

  // --------------------------------------------------------------- joint sliders
  var box = $("joint-sliders");
  data.sliders.forEach(function (s) {
    var label = document.createElement("label");
    label.className = "slider";
    var title = document.createElement("span");
    title.textContent = s.name + (s.continuous ? " (continuous)" : "");
    var input = document.createElement("input");
    input.type = "range";
    input.name = s.name;
    input.min = String(s.lower);
    input.max = String(s.upper);
    input.step = "any";
    input.title = s.name + ": [" + s.lower + ", " + s.upper + "] " + s.unit + " (SI)";
    var output = document.createElement("output");
    label.appendChild(title);
    label.appendChild(input);
    label.appendChild(output);
    box.appendChild(label);
    var entry = { index: s.index, unit: s.unit, input: input, output: output };
    sliders.push(entry);
    input.addEventListener("input", function () {
      if (player) player.pause();
      q[s.index] = Number(input.value);
      output.textContent = sliderText(entry, q[s.index]);
      applyQ();
      if (teach) sendQ(); else showScenePose();
    });
  });

  function showScenePose() { showPose(scenePose()); }

  // --------------------------------------------------------------- motion player (--traj)
  var player = null;
  if (data.motion) {
    var m = data.motion, duration = m.times[m.times.length - 1];
    var time = $("time"), timeValue = $("time-value"), play = $("play");
    time.max = String(duration);
    var playing = false, origin = 0;
    var setTime = function (t) {
      var k = 0, hi = m.times.length - 1;
      while (k < hi && m.times[k + 1] <= t) k++;
      var row = m.qs[k];
      if (k < hi) {
        var a = (t - m.times[k]) / (m.times[k + 1] - m.times[k]), next = m.qs[k + 1];
        row = row.map(function (v, i) { return v + a * (next[i] - v); });
      }
      q = row.slice();
      (m.shown || []).forEach(function (s) {  // nodes shown over spans of the motion (a job's boxes)
        var on = s.spans.some(function (w) { return t >= w[0] && t < w[1]; });
        var n = node(s.path);
        if (n) n.set_property("visible", on);
      });
      time.value = String(t);
      timeValue.textContent = t.toFixed(3) + " s";
      syncSliders();
      applyQ();
      showScenePose();
    };
    var frame = function (now) {
      if (!playing) return;
      var t = (now - origin) / 1000;
      if (t >= duration) {
        if (m.loop && duration > 0) { t = t % duration; } else { t = duration; player.pause(); }
      }
      setTime(t);
      if (playing) requestAnimationFrame(frame);
    };
    player = {
      play: function () {
        if (Number(time.value) >= duration) time.value = "0";
        playing = true;
        play.textContent = "pause";
        origin = performance.now() - Number(time.value) * 1000;
        requestAnimationFrame(frame);
      },
      pause: function () { playing = false; play.textContent = "play"; },
      playing: function () { return playing; },
      seek: function (t) { player.pause(); setTime(Math.min(Math.max(t, 0), duration)); },
    };
    play.addEventListener("click", function () { if (playing) player.pause(); else player.play(); });
    time.addEventListener("input", function () { player.seek(Number(time.value)); });
    window.scaraPlayer = player;
  }

  // --------------------------------------------------------------- units switch
  function relabel() {
    Array.prototype.forEach.call(document.querySelectorAll(".u-len"), function (e) { e.textContent = lengthUnit(); });
    Array.prototype.forEach.call(document.querySelectorAll(".u-ang"), function (e) { e.textContent = angleUnit(); });
    if (lastPose) showPose(lastPose);
    if (lastQ) showJoints(lastQ);
    syncSliders();
    if (teach) { relabelJog(); showPoints(lastPoints); showStatus(); showCell(); }
  }
  // A step field keeps the SI value it stands for: the switch shows it in the new unit (12 digits), and a jog
  // sent while the field still shows that text sends the SI value itself, not the rounded text read back
  // (180 deg is pi, not 3.14159265359 > pi). Typing in the field forgets it.
  var STEP_FIELDS = [["jog-step", "length"], ["jog-step-angle", "angle"]];
  Array.prototype.forEach.call(document.querySelectorAll("input[name=units]"), function (radio) {
    radio.addEventListener("change", function () {
      if (!radio.checked) return;
      var steps = STEP_FIELDS.map(function (pair) { var input = $(pair[0]); return input ? typedStep(input, pair[1]) : null; });
      units = radio.value;
      STEP_FIELDS.forEach(function (pair, i) {
        var input = $(pair[0]), si = steps[i];
        if (!input || si === null) return;
        input.value = String(Number(toUnit(si, pair[1]).toPrecision(12)));
        input.dataset.si = String(si);
        input.dataset.shown = input.value;
      });
      relabel();
    });
  });
  // the SI value a step field stands for (null when it is not a finite number)
  function typedStep(input, kind) {
    if (input.dataset.shown !== undefined && input.value === input.dataset.shown) return Number(input.dataset.si);
    var text = input.value.trim(), v = Number(text);
    return text !== "" && isFinite(v) ? fromUnit(v, kind) : null;
  }

  // --------------------------------------------------------------- meshcat's controls
  var showControls = $("show-controls");
  if (showControls) {
    showControls.checked = viewer.gui.domElement.style.display !== "none" || !!data.controls;
    var setControls = function () { viewer.gui.domElement.style.display = showControls.checked ? "" : "none"; };
    showControls.addEventListener("change", setControls);
    setControls();
  }

  // --------------------------------------------------------------- live teach page
  var chain = Promise.resolve(), pendingQ = false;

  // Words. A sentence of the server writes each length or angle "<number> m", "rad" or "deg" (SI, or the
  // workspace's degrees): shown in the page's units, rounded to the readouts' resolution, zeros dropped.
  var NUMBER = "-?\\d+(?:\\.\\d+)?(?:e[-+]?\\d+)?";
  var QUANTITY = new RegExp("(?<![\\w.])(?:\\[(" + NUMBER + "), (" + NUMBER + ")\\]|(" + NUMBER + ")) (m|rad|deg)(?![\\w/^\u00b2])", "g");
  function localise(text) {
    return String(text).replace(QUANTITY, function (all, lo, hi, one, unit) {
      var kind = unit === "m" ? "length" : "angle", scale = unit === "deg" ? DEG : 1;
      var show = function (v) { return number(Number(v) * scale, kind); };
      return (one !== undefined ? show(one) : "[" + show(lo) + ", " + show(hi) + "]") + " " + unitOf(kind);
    });
  }
  // the cell's line (teach --cell): the server's words, in the page's units
  function showCell() { var info = $("cell-info"); if (info) info.textContent = localise(info.dataset.text); }
  function code(status) { return String(status).toLowerCase().replace(/_/g, " "); }  // OUT_OF_REACH: out of reach

  // The status line: the answer to the last thing the user did. It is a function of the page's units (the
  // switch restates it) and stays until the user's next action: answers to the page's own requests (the
  // keep-alive of a held button) never replace a reason a jog stopped.
  var status = function () { return ["-", ""]; };
  function showStatus() {
    var said = status(), line = $("ik-status");
    line.textContent = said[0];
    line.className = said[1];
  }
  function say(text, kind) { status = function () { return [typeof text === "function" ? text() : text, kind]; }; showStatus(); }
  function travel(r) { return amount(r.travelled, r.angle ? "angle" : "length"); }
  function refusal(r) {
    if (r.error) return ["refused: " + localise(r.error), "refused"];
    return ["refused: " + code(r.status) + ": " + localise(r.message), "refused"];
  }

  function request(route, body) {
    return fetch(teach.api + route, {
      method: body === null ? "GET" : "POST",
      headers: body === null ? {} : { "Content-Type": "application/json" },
      body: body === null ? undefined : JSON.stringify(body),
    }).then(function (r) { return r.json(); });
  }
  // post one request after the earlier ones; words(r) -> [text, class] (null: the status line is kept)
  function post(route, body, words) {
    if (words) recorded = null;
    chain = chain.then(function () {
      return request(route, body).then(function (r) {
        applyReply(r);
        if (words) status = function () { return r.error ? refusal(r) : words(r); };
        if (words) showStatus();
        return r;
      }).catch(function (err) {
        say("no answer from the server: " + err, "refused");
      });
    });
    return chain;
  }
  function applyReply(r) {
    window.scaraReplies = (window.scaraReplies || 0) + 1;
    if (r.error) return r;
    q = r.q.slice();
    syncSliders();
    applyQ();
    showPose(r.pose);
    showJoints(r.q);
    $("branch-now").textContent = r.branch || "-";
    if (r.points) showPoints(r.points);
    return r;
  }
  function sendQ() {
    if (pendingQ) return;
    pendingQ = true;
    chain = chain.then(function () { pendingQ = false; });
    if (hold) endHold(true);
    post("/q", { q: q.slice() }, function (r) {
      return r.moved ? ["moved to the sliders' joint values", "ok"] : refusal(r);
    });
  }

  // the jog grid: rows are J1..J4 (joint frame) or x, y, z, rz (base and tool frames)
  function jogFrame() { return document.querySelector("input[name=frame]:checked").value; }
  function jogMode() { return document.querySelector("input[name=jogmode]:checked").value; }
  function rowKind(row) {
    if (jogFrame() === "joint") return jointKind(row);
    return row === 3 ? "angle" : "length";
  }
  function rowLabel(row) {
    if (jogFrame() === "joint") return data.sliders[row] ? data.sliders[row].name : "J" + (row + 1);
    return ["x", "y", "z", "rz"][row];
  }
  function relabelJog() {
    for (var i = 0; i < 4; i++) {
      var label = rowLabel(i);
      $("jog-label-" + i).textContent = label;
      $("jog-" + i + "-").textContent = label + " \u2212";
      $("jog-" + i + "+").textContent = label + " +";
      $("jog-" + i + "-").disabled = $("jog-" + i + "+").disabled = jogFrame() === "joint" && !data.sliders[i];
    }
  }
  // what a jog moves, in words: "joint2 +", "x \u2212"; and " in the tool frame" for a jog along the tool's axes
  function jogName(row, sign) { return rowLabel(row) + " " + (sign > 0 ? "+" : "\u2212"); }
  function frameWords() { return jogFrame() === "tool" ? " in the tool frame" : ""; }
  // the step of a row's kind, in SI, or null after saying why in the status line (nothing is sent)
  function stepFor(kind) {
    var input = kind === "angle" ? $("jog-step-angle") : $("jog-step");
    var range = kind === "angle" ? teach.step_angle : teach.step_length;
    var text = input.value.trim(), si = typedStep(input, kind);
    // the ends with the server's tolerance (STEP_TOL): the 12 digits a switched step shows are inside
    var ok = si !== null && si >= range[0] * (1 - teach.step_tol) && si <= range[1] * (1 + teach.step_tol);
    input.setAttribute("aria-invalid", ok ? "false" : "true");
    if (!ok) {
      var shown = text !== "" ? "'" + text + "'" : (input.validity.badInput ? "not a number" : "empty");
      say(function () {
        var lo = toUnit(range[0], kind), hi = toUnit(range[1], kind);
        return "refused: the step for " + (kind === "angle" ? "angles" : "lengths") + " is " + shown + "; it must " +
          "be a number from " + Number(lo.toPrecision(6)) + " to " + Number(hi.toPrecision(6)) + " " + unitOf(kind) +
          " (the + and \u2212 buttons give the sense)";
      }, "refused");
      return null;
    }
    return Math.min(si, range[1]);
  }
  function motionBody(row, sign) {
    var body = { direction: sign };
    if (jogFrame() === "joint") body.joint = row;
    else { body.axis = ["x", "y", "z", "yaw"][row]; body.frame = jogFrame(); }
    return body;
  }
  // how a jog that did not go the whole way ended: the reason in the page's units, and how far it went
  function stopped(r, of) {
    var reason = localise(r.reason ? r.reason.text : r.message);
    if (!(r.travelled > 0)) return ["not moved: " + reason, "stopped"];
    var kind = r.angle ? "angle" : "length";
    var moved = of ? number(r.travelled, kind) + " of " + amount(r.requested, kind) : travel(r);
    return [reason + " \u2014 moved " + moved, "stopped"];
  }
  function jogStep(row, sign) {
    var kind = rowKind(row), step = stepFor(kind);
    if (step === null) return;
    if (hold) endHold(true);
    var body = motionBody(row, sign), name = jogName(row, sign), frame = frameWords();
    body.step = step;
    post("/jog", body, function (r) {
      if (r.status === "OK" && r.moved) return ["jogged " + name + " " + travel(r) + frame, "ok"];
      return stopped(r, true);
    }).then(function () { window.scaraJogs = (window.scaraJogs || 0) + 1; });
  }

  // Hold-to-jog: the server moves while it hears "still held" (a keep-alive) within its watchdog; the page says
  // "released" at once. The keep-alive is posted by a Worker, on a thread of its own: a slow frame on the page's
  // thread (software WebGL at full HD on a busy PC) cannot delay it. And while a button is held, a frame slower
  // than a control period (the server's step, 50 ms) is not drawn: the page's thread stays free for the button
  // going up (a frame under way would delay the release by what is left of it). The readouts keep up; the view
  // is drawn on release.
  var hold = null, holds = 0;
  function slowFrames() { return renderCost > teach.control_period * 1000; }
  var WORKER = [
    "var timer = null;",
    "onmessage = function (e) {",
    "  var m = e.data;",
    "  if (timer !== null) { clearInterval(timer); timer = null; }",
    "  if (!m.url) return;",
    "  var alive = function () {",
    "    fetch(m.url, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}' })",
    "      .then(function (r) { return r.json(); })",
    "      .then(function (r) { postMessage({ hold: m.hold, reply: r }); },",
    "            function (err) { postMessage({ hold: m.hold, error: String(err) }); });",
    "  };",
    "  alive();",
    "  timer = setInterval(alive, m.every);",
    "};",
  ].join("\n");
  var renderCost = 0;  // [ms] the last frame drawn: from its drawing to the next animation frame
  var keepAlive = null;  // made with the page, not at the first hold: a worker can take long to start on a busy PC
  function makeKeepAlive() {
    try {
      keepAlive = new Worker(URL.createObjectURL(new Blob([WORKER], { type: "text/javascript" })));
      keepAlive.onmessage = function (e) { kept(e.data); };
    } catch (err) {  // no Worker here: the page's own timer (exposed to slow frames)
      var timer = null;
      keepAlive = { postMessage: function (m) {
        clearInterval(timer);
        if (!m.url) return;
        var alive = function () {
          request("/alive", {}).then(function (r) { kept({ hold: m.hold, reply: r }); },
                                     function (err) { kept({ hold: m.hold, error: String(err) }); });
        };
        alive();
        timer = setInterval(alive, m.every);
      } };
    }
  }
  function startKeepAlive(h) {
    keepAlive.postMessage({ url: new URL(teach.api + "/alive", location.href).href, every: teach.keepalive * 1000,
                            hold: h.id });
  }
  // an answer to the keep-alive: the robot's new q, and the hold's end when the server ended it
  function kept(m) {
    if (!hold || m.hold !== hold.id) return;  // a late answer for a hold already ended
    var h = hold;
    if (m.error || m.reply.error) {
      endHold(true);
      say("no answer from the server: " + (m.error || m.reply.error), "refused");
      return;
    }
    applyReply(m.reply);
    if (m.reply.holding) {
      h.last = m.reply;
      showStatus();
    } else {
      endHold(false);
      status = function () { return ended(h, m.reply); };
      showStatus();
    }
  }
  function ended(h, r) {
    if (!r.reason || r.reason.kind === "released") return ["released " + h.name + " \u2014 moved " + travel(r), "ok"];
    return stopped(r, false);
  }
  function holding(h) {
    var r = h.last, paused = slowFrames() ? "; frames take " + Math.round(renderCost) + " ms here: the view is drawn " +
      "on release" : "";
    return ["jogging " + h.name + " at " + h.speed + " %" + (r ? ": " + travel(r) : "") + " (release to stop" + paused +
      ")", "ok"];
  }
  function startHold(row, sign, button) {
    if (hold) endHold(true);
    var body = motionBody(row, sign);
    body.speed = Number($("speed").value);
    var mine = hold = { id: ++holds, button: button, started: false, name: jogName(row, sign) + frameWords(), speed: body.speed,
                        last: null };
    button.classList.add("held");
    status = function () { return holding(mine); };
    showStatus();
    post("/hold", body, null).then(function (r) {
      if (hold !== mine) return;  // released before the server answered: the release follows the hold
      if (!r || r.error) {
        endHold(false);
        if (r) { status = function () { return refusal(r); }; showStatus(); }
        return;
      }
      mine.started = true;
      startKeepAlive(mine);
    });
  }
  function endHold(send) {
    if (!hold) return;
    var h = hold;
    hold = null;
    if (keepAlive !== null) keepAlive.postMessage({ url: null });
    h.button.classList.remove("held");
    viewer.set_dirty();  // the pose it stopped at, drawn at the next frame
    if (send) {
      post("/release", {}, function (r) { return ended(h, r); }).then(function (r) {
        window.scaraReleases = (window.scaraReleases || 0) + 1;
        window.scaraReleaseAnswered = performance.now();
        window.scaraReleaseMessage = r && r.message;
      });
    }
  }
  if (teach) {
    makeKeepAlive();
    // a frame's cost as the page's thread sees it: from the drawing to the next animation frame (the WebGL
    // calls return at once; with software WebGL the wait for the drawn frame falls on the next one)
    var renderFrame = viewer.render.bind(viewer);
    viewer.render = function () {
      if (hold && slowFrames()) return;  // needs_render stays set: drawn on release
      var start = performance.now();
      renderFrame();
      requestAnimationFrame(function () { renderCost = performance.now() - start; });
    };
    for (var row = 0; row < 4; row++) {
      [["-", -1], ["+", 1]].forEach(function (pair) {
        var r = row, button = $("jog-" + r + pair[0]);
        button.addEventListener("click", function () { if (jogMode() === "step") jogStep(r, pair[1]); });
        button.addEventListener("pointerdown", function (evt) {
          if (jogMode() !== "hold" || evt.button !== 0) return;
          button.setPointerCapture(evt.pointerId);
          startHold(r, pair[1], button);
        });
        ["pointerup", "pointercancel", "lostpointercapture"].forEach(function (name) {
          button.addEventListener(name, function () { if (hold && hold.button === button) endHold(true); });
        });
      });
    }
    window.addEventListener("blur", function () { endHold(true); });
    document.addEventListener("visibilitychange", function () { if (document.hidden) endHold(true); });
    window.addEventListener("pagehide", function () {
      if (!hold) return;
      hold = null;  // the page goes away: a last release that outlives it (the server's watchdog is the backstop)
      fetch(teach.api + "/release", { method: "POST", keepalive: true,
        headers: { "Content-Type": "application/json" }, body: "{}" });
    });
    Array.prototype.forEach.call(document.querySelectorAll("input[name=frame]"), function (radio) {
      radio.addEventListener("change", relabelJog);
    });
    $("speed").addEventListener("input", function () { $("speed-value").textContent = $("speed").value + " %"; });
    STEP_FIELDS.forEach(function (pair) {
      $(pair[0]).addEventListener("input", function () {
        var input = $(pair[0]);
        input.removeAttribute("aria-invalid");
        delete input.dataset.si;
        delete input.dataset.shown;
      });
    });
    relabelJog();
    showCell();

    $("goto").addEventListener("submit", function (evt) {
      evt.preventDefault();
      var f = evt.target, pose = [], names = ["x", "y", "z", "yaw"];
      for (var i = 0; i < 4; i++) {
        var v = Number(f[names[i]].value);
        if (!isFinite(v)) { say("refused: " + names[i] + " must be a number", "refused"); return; }
        pose.push(fromUnit(v, POSE_KINDS[i]));
      }
      if (hold) endHold(true);
      post("/goto", { pose: pose, branch: $("branch").value }, function (r) {
        return r.moved ? ["moved to the pose (" + r.solver + " IK, " + (r.branch || "one") + " branch)", "ok"]
          : refusal(r);
      });
    });

    // points: record, rename (edit the name), go to, delete; save / reload the server's file
    // a recorded point: said in the status line (its name and pose), and its row marked and scrolled into view
    $("record").addEventListener("click", function () {
      var name = $("point-name").value.trim(), before = lastPoints.map(function (p) { return p.name; });
      var added = function (r) { return (r.points || []).filter(function (p) { return before.indexOf(p.name) < 0; })[0]; };
      var body = { form: $("point-form").value };
      if (name) body.name = name;
      post("/points/record", body, function (r) {
        var p = added(r);
        return ["recorded " + p.name + " at x " + number(p.pose[0], "length") + ", y " + number(p.pose[1], "length") +
          ", z " + amount(p.pose[2], "length") + ", yaw " + amount(p.pose[3], "angle"), "ok"];
      }).then(function (r) {
        if (!r || r.error || !added(r)) return;
        $("point-name").value = "";
        recorded = added(r).name;
        showPoints(r.points);
        document.querySelector("#points tr.recorded").scrollIntoView({ block: "nearest" });
      });
    });
    var said = function (r) { return [localise(r.message), "ok"]; };
    $("points-save").addEventListener("click", function () { post("/points/save", {}, said); });
    $("points-load").addEventListener("click", function () { post("/points/load", {}, said); });
    post("/state", null, function () { return ["ready: jog, go to a pose or record points", "ok"]; });
  } else {
    syncSliders();
    applyQ();
    showScenePose();
  }

  var recorded = null;  // the point just recorded: its row is marked until the user's next action
  function showPoints(points) {
    lastPoints = points;
    if (typeof setLabels === "function") {
      setLabels("points", points.filter(function (p) { return p.pose; }).map(function (p) {
        return { text: p.name, xyz: p.pose.slice(0, 3) };
      }));
    }
    var body = document.querySelector("#points tbody");
    if (!body) return;
    body.textContent = "";
    points.forEach(function (p) {
      var tr = document.createElement("tr");
      tr.dataset.point = p.name;
      var name = document.createElement("input");
      name.value = p.name;
      name.title = "rename: type a new name, then Enter";
      name.setAttribute("aria-label", "name of " + p.name);
      name.addEventListener("change", function () {
        var to = name.value.trim();
        post("/points/rename", { old: p.name, new: to }, function () { return ["renamed " + p.name + " to " + to, "ok"]; });
      });
      var pose = document.createElement("td");
      pose.className = "pose";
      pose.textContent = p.pose ? p.pose.map(function (v, i) { return fmt(v, POSE_KINDS[i]); }).join(" ") : "";
      pose.title = "x y z [" + lengthUnit() + "] yaw [" + angleUnit() + "]";
      var go = document.createElement("button");
      go.type = "button";
      go.textContent = "go";
      go.addEventListener("click", function () {
        if (hold) endHold(true);
        post("/points/goto", { name: p.name }, function (r) { return r.moved ? ["moved to " + p.name, "ok"] : refusal(r); });
      });
      var del = document.createElement("button");
      del.type = "button";
      del.textContent = "\u00d7";
      del.title = "delete " + p.name;
      del.addEventListener("click", function () { post("/points/delete", { name: p.name }, function () { return ["deleted " + p.name, "ok"]; }); });
      var cell = document.createElement("td");
      cell.appendChild(name);
      tr.appendChild(cell);
      tr.appendChild(pose);
      [go, del].forEach(function (b) { var td = document.createElement("td"); td.appendChild(b); tr.appendChild(td); });
      if (p.name === recorded) tr.className = "recorded";
      body.appendChild(tr);
    });
  }

  // --------------------------------------------------------------- labels: the obstacles' and the points' names
  // Written over the scene at their places (base frame), projected with the camera on every frame: the
  // obstacles of the cell, the poses a job reaches, the taught points of the pendant (updated as they change).
  var labelLayer = document.createElement("div");
  labelLayer.id = "labels";
  labelLayer.style.cssText = "position:absolute;inset:0;pointer-events:none;overflow:hidden;";
  $("scene").appendChild(labelLayer);
  var labels = [], placing = false;
  function setLabels(group, items) {
    labels = labels.filter(function (l) {
      if (l.group !== group) return true;
      l.el.remove();
      return false;
    });
    items.forEach(function (item) {
      var el = document.createElement("span");
      el.className = "label label-" + group;
      el.textContent = item.text;
      el.style.cssText = "position:absolute;transform:translate(-50%,-120%);font:11px system-ui,sans-serif;" +
        "background:rgba(255,255,255,.8);border:1px solid #c9ced6;padding:0 3px;white-space:nowrap;";
      labelLayer.appendChild(el);
      labels.push({ group: group, xyz: item.xyz, el: el });
    });
    if (labels.length && !placing) {  // follow the camera on every frame while there are labels, only then
      placing = true;
      window.requestAnimationFrame(placeLabels);
    }
  }
  function placeLabels() {
    if (!labels.length) { placing = false; return; }
    var base = node(data.base).object, rect = labelLayer.getBoundingClientRect();
    base.updateMatrixWorld(true);
    labels.forEach(function (l) {
      var v = base.localToWorld(new THREE.Vector3(l.xyz[0], l.xyz[1], l.xyz[2])).project(viewer.camera);
      var inside = v.z > -1 && v.z < 1 && Math.abs(v.x) <= 1.05 && Math.abs(v.y) <= 1.05;
      l.el.style.display = inside ? "" : "none";
      l.el.style.left = ((v.x + 1) / 2 * rect.width) + "px";
      l.el.style.top = ((1 - v.y) / 2 * rect.height) + "px";
    });
    window.requestAnimationFrame(placeLabels);
  }
  var groups = {};
  (data.labels || []).forEach(function (l) { (groups[l.group] = groups[l.group] || []).push(l); });
  Object.keys(groups).forEach(function (g) { setLabels(g, groups[g]); });

  if (units !== "mm") {  // open in the units asked for: the switch and every label follow
    var opened = document.querySelector("input[name=units][value=" + units + "]");
    if (opened) opened.checked = true;
    relabel();
  }

  // camera: look at the workspace's centre (scene z-up -> three.js y-up: (x, y, z) -> (x, z, -y))
  var c = data.camera, t = data.target;
  viewer.camera.position.set(c[0], c[2], -c[1]);
  viewer.controls.target.set(t[0], t[2], -t[1]);
  viewer.controls.update();
  viewer.set_dirty();
  if (player && data.motion.play) player.play(); else if (player) player.seek(0);
  window.scaraPendant = { applyQ: applyQ, scenePose: scenePose, q: function () { return q.slice(); } };
})();
