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
  var units = "mm";
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
    if (teach) { relabelJog(); showPoints(lastPoints); }
  }
  Array.prototype.forEach.call(document.querySelectorAll("input[name=units]"), function (radio) {
    radio.addEventListener("change", function () {
      if (!radio.checked) return;
      var before = units;
      units = radio.value;
      // the typed steps keep their meaning: converted to the new unit
      [["jog-step", "length"], ["jog-step-angle", "angle"]].forEach(function (pair) {
        var input = $(pair[0]);
        if (!input) return;
        var v = Number(input.value);
        if (input.value.trim() !== "" && isFinite(v)) {
          units = before;
          var si = fromUnit(v, pair[1]);
          units = radio.value;
          input.value = String(Number(toUnit(si, pair[1]).toPrecision(12)));
        }
      });
      relabel();
    });
  });

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
  function say(text, kind) {
    var status = $("ik-status");
    status.textContent = text;
    status.className = kind;
  }
  function request(route, body) {
    return fetch(teach.api + route, {
      method: body === null ? "GET" : "POST",
      headers: body === null ? {} : { "Content-Type": "application/json" },
      body: body === null ? undefined : JSON.stringify(body),
    }).then(function (r) { return r.json(); });
  }
  function post(route, body) {
    chain = chain.then(function () {
      return request(route, body).then(applyReply).catch(function (err) {
        say("no answer from the server: " + err, "refused");
      });
    });
    return chain;
  }
  function travelled(r) {
    var kind = r.angle ? "angle" : "length";
    return fmt(r.travelled, kind) + " of " + fmt(r.requested, kind) + " " + unitOf(kind);
  }
  function applyReply(r) {
    window.scaraReplies = (window.scaraReplies || 0) + 1;
    if (r.error) {
      say("error: " + r.error, "refused");
      return r;
    }
    q = r.q.slice();
    syncSliders();
    applyQ();
    showPose(r.pose);
    showJoints(r.q);
    $("branch-now").textContent = r.branch || "-";
    if (r.points) showPoints(r.points);
    if (r.status === "STOPPED") {
      say("STOPPED after " + travelled(r) + ": " + r.message, "stopped");
    } else if (r.moved || r.status === "OK") {
      say(r.message ? "OK: " + r.message : "OK (" + r.solver + ")", "ok");
    } else {
      say("refused: " + r.status + ": " + r.message, "refused");
    }
    if (hold && !r.holding && hold.started) endHold(false);
    return r;
  }
  function sendQ() {
    if (pendingQ) return;
    pendingQ = true;
    chain = chain.then(function () { pendingQ = false; });
    post("/q", { q: q.slice() });
  }

  // the jog grid: rows are J1..J4 (joint frame) or x, y, z, rz (base and tool frames)
  function jogFrame() { return document.querySelector("input[name=frame]:checked").value; }
  function jogMode() { return document.querySelector("input[name=jogmode]:checked").value; }
  function rowKind(row) {
    if (jogFrame() === "joint") return jointKind(row);
    return row === 3 ? "angle" : "length";
  }
  function relabelJog() {
    for (var i = 0; i < 4; i++) {
      var label = jogFrame() === "joint" ? (data.sliders[i] ? data.sliders[i].name : "J" + (i + 1))
        : ["x", "y", "z", "rz"][i];
      $("jog-label-" + i).textContent = label;
      $("jog-" + i + "-").textContent = label + " \u2212";
      $("jog-" + i + "+").textContent = label + " +";
      $("jog-" + i + "-").disabled = $("jog-" + i + "+").disabled = jogFrame() === "joint" && !data.sliders[i];
    }
  }
  // the step of a row's kind, in SI, or null after saying why in the status line (nothing is sent)
  function stepFor(kind) {
    var input = kind === "angle" ? $("jog-step-angle") : $("jog-step");
    var range = kind === "angle" ? teach.step_angle : teach.step_length;
    var text = input.value.trim(), v = Number(text);
    var lo = toUnit(range[0], kind), hi = toUnit(range[1], kind);
    var ok = text !== "" && isFinite(v) && v > 0;
    var si = ok ? fromUnit(v, kind) : NaN;
    ok = ok && si >= range[0] * (1 - 1e-12) && si <= range[1];
    input.setAttribute("aria-invalid", ok ? "false" : "true");
    if (!ok) {
      var shown = text !== "" ? "'" + text + "'" : (input.validity.badInput ? "not a number" : "empty");
      say("refused: the step for " + (kind === "angle" ? "angles" : "lengths") + " is " + shown + "; it must be a " +
        "number from " + Number(lo.toPrecision(6)) + " to " + Number(hi.toPrecision(6)) + " " + unitOf(kind) +
        " (the + and \u2212 buttons give the sense)", "refused");
      return null;
    }
    return si;
  }
  function motionBody(row, sign) {
    var body = { direction: sign };
    if (jogFrame() === "joint") body.joint = row;
    else { body.axis = ["x", "y", "z", "yaw"][row]; body.frame = jogFrame(); }
    return body;
  }
  function jogStep(row, sign) {
    var kind = rowKind(row), step = stepFor(kind);
    if (step === null) return;
    var body = motionBody(row, sign);
    body.step = step;
    post("/jog", body).then(function () { window.scaraJogs = (window.scaraJogs || 0) + 1; });
  }
  // hold-to-jog: the server moves; this page says "still held" every keep-alive and "released" at once
  var hold = null;
  function startHold(row, sign, button) {
    if (hold) endHold(true);
    var body = motionBody(row, sign);
    body.speed = Number($("speed").value);
    hold = { button: button, timer: null, started: false };
    button.classList.add("held");
    var mine = hold;
    post("/hold", body).then(function (r) {
      if (hold !== mine) return;
      if (!r || r.error) { endHold(false); return; }
      mine.started = true;
      mine.timer = setInterval(function () { post("/alive", {}); }, teach.keepalive * 1000);
    });
  }
  function endHold(send) {
    if (!hold) return;
    var h = hold;
    hold = null;
    if (h.timer !== null) clearInterval(h.timer);
    h.button.classList.remove("held");
    if (send) {
      post("/release", {}).then(function (r) {
        window.scaraReleases = (window.scaraReleases || 0) + 1;
        window.scaraReleaseAnswered = performance.now();
        window.scaraReleaseMessage = r && r.message;
      });
    }
  }
  if (teach) {
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
    ["jog-step", "jog-step-angle"].forEach(function (id) {
      $(id).addEventListener("input", function () { $(id).removeAttribute("aria-invalid"); });
    });
    relabelJog();

    $("goto").addEventListener("submit", function (evt) {
      evt.preventDefault();
      var f = evt.target, pose = [], names = ["x", "y", "z", "yaw"];
      for (var i = 0; i < 4; i++) {
        var v = Number(f[names[i]].value);
        if (!isFinite(v)) { say("refused: " + names[i] + " must be a number", "refused"); return; }
        pose.push(fromUnit(v, POSE_KINDS[i]));
      }
      post("/goto", { pose: pose, branch: $("branch").value });
    });

    // points: record, rename (edit the name), go to, delete; save / reload the server's file
    $("record").addEventListener("click", function () {
      var name = $("point-name").value.trim();
      post("/points/record", name ? { name: name } : {}).then(function () { $("point-name").value = ""; });
    });
    var fileButtons = [["points-save", "/points/save"], ["points-load", "/points/load"]];
    fileButtons.forEach(function (pair) { $(pair[0]).addEventListener("click", function () { post(pair[1], {}); }); });
    post("/state", null);
  } else {
    syncSliders();
    applyQ();
    showScenePose();
  }

  function showPoints(points) {
    lastPoints = points;
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
        post("/points/rename", { old: p.name, new: name.value.trim() });
      });
      var pose = document.createElement("td");
      pose.className = "pose";
      pose.textContent = p.pose ? p.pose.map(function (v, i) { return fmt(v, POSE_KINDS[i]); }).join(" ") : "";
      pose.title = "x y z [" + lengthUnit() + "] yaw [" + angleUnit() + "]";
      var go = document.createElement("button");
      go.type = "button";
      go.textContent = "go";
      go.addEventListener("click", function () { post("/points/goto", { name: p.name }); });
      var del = document.createElement("button");
      del.type = "button";
      del.textContent = "\u00d7";
      del.title = "delete " + p.name;
      del.addEventListener("click", function () { post("/points/delete", { name: p.name }); });
      var cell = document.createElement("td");
      cell.appendChild(name);
      tr.appendChild(cell);
      tr.appendChild(pose);
      [go, del].forEach(function (b) { var td = document.createElement("td"); td.appendChild(b); tr.appendChild(td); });
      body.appendChild(tr);
    });
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
