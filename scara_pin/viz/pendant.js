// scara-pin's pendant: joint sliders, the tool pose readout, a motion player and (live) Cartesian jogging.
// Moves the robot through meshcat's scene tree: each joint is a node, whose transform is its placement
// times its own rotation about (or translation along) its axis; nothing else of the kinematics is here.
// The readout is read from three.js's world matrices (offline) or is the server's Pinocchio FK (teach).
(function () {
  "use strict";
  var THREE = MeshCat.THREE;
  var data = JSON.parse(document.getElementById("scara-data").textContent);
  var q = data.q.slice();
  var teach = data.teach || null;
  var sliders = [];

  function node(path) { return viewer.scene_tree.find(path.split("/")); }
  function $(id) { return document.getElementById(id); }

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

  // tool0 in the base frame, from the scene graph: (x, y, z [m], yaw [rad])
  function scenePose() {
    viewer.scene.updateMatrixWorld(true);
    var base = node(data.base).object.matrixWorld, tool = node(data.tool).object.matrixWorld;
    var rel = new THREE.Matrix4().copy(base).invert().multiply(tool);
    var e = rel.elements;  // column-major
    return [e[12], e[13], e[14], Math.atan2(e[1], e[0])];
  }

  function showPose(texts) {
    var names = ["x", "y", "z", "yaw"], units = ["m", "m", "m", "rad"], lines = [];
    for (var i = 0; i < 4; i++) lines.push(names[i] + " = " + texts[i] + " " + units[i]);
    $("tool-pose").textContent = lines.join("\n");
  }

  function showScenePose() {
    showPose(scenePose().map(function (v) { return v.toFixed(9); }));
  }

  function human(s, value) {
    if (s.unit === "rad") return value.toFixed(6) + " rad (" + (value * 180 / Math.PI).toFixed(3) + "\u00b0)";
    return value.toFixed(6) + " m (" + (value * 1000).toFixed(3) + " mm)";
  }

  function syncSliders() {
    sliders.forEach(function (s) {
      s.input.value = String(q[s.index]);
      s.output.textContent = human(s, q[s.index]);
    });
  }

  // --------------------------------------------------------------- joint sliders
  var box = $("joint-sliders");
  data.sliders.forEach(function (s) {
    var label = document.createElement("label");
    label.className = "slider";
    var title = document.createElement("span");
    title.textContent = s.name + " [" + s.unit + "]" + (s.continuous ? " (continuous)" : "");
    var input = document.createElement("input");
    input.type = "range";
    input.name = s.name;
    input.min = String(s.lower);
    input.max = String(s.upper);
    input.step = "any";
    input.title = s.name + ": [" + s.lower + ", " + s.upper + "] " + s.unit;
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
      output.textContent = human(entry, q[s.index]);
      applyQ();
      if (teach) sendQ(); else showScenePose();
    });
  });

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

  // --------------------------------------------------------------- live teach page
  var chain = Promise.resolve(), pendingQ = false;
  function post(route, body) {
    chain = chain.then(function () {
      return fetch(teach.api + route, {
        method: body === null ? "GET" : "POST",
        headers: body === null ? {} : { "Content-Type": "application/json" },
        body: body === null ? undefined : JSON.stringify(body),
      }).then(function (r) { return r.json(); }).then(applyReply).catch(function (err) {
        $("ik-status").textContent = "no answer from the server: " + err;
        $("ik-status").className = "refused";
      });
    });
    return chain;
  }
  function applyReply(r) {
    if (r.error) {
      $("ik-status").textContent = "error: " + r.error;
      $("ik-status").className = "refused";
      return;
    }
    q = r.q.slice();
    syncSliders();
    applyQ();
    showPose(r.pose_text);
    $("joint-values").textContent = data.sliders.map(function (s) {
      return s.name + " = " + r.q_text[s.index] + " " + s.unit;
    }).join("\n");
    $("branch-now").textContent = r.branch;
    var status = $("ik-status");
    status.className = r.moved ? "ok" : "refused";
    status.textContent = r.moved ? r.status + " (" + r.solver + ")" : "refused: " + r.status + ": " + r.message;
    window.scaraReplies = (window.scaraReplies || 0) + 1;
  }
  function sendQ() {
    if (pendingQ) return;
    pendingQ = true;
    chain = chain.then(function () { pendingQ = false; });
    post("/q", { q: q.slice() });
  }
  function step() {
    var v = Number($("jog-step").value);
    return isFinite(v) ? v : NaN;
  }
  if (teach) {
    ["x", "y", "z", "yaw"].forEach(function (axis) {
      [["+", 1], ["-", -1]].forEach(function (pair) {
        $("jog-" + axis + pair[0]).addEventListener("click", function () {
          post("/jog", { axis: axis, step: pair[1] * step(), branch: $("branch").value });
        });
      });
    });
    $("goto").addEventListener("submit", function (evt) {
      evt.preventDefault();
      var f = evt.target;
      post("/goto", {
        pose: [Number(f.x.value), Number(f.y.value), Number(f.z.value), Number(f.yaw.value)],
        branch: $("branch").value,
      });
    });
    post("/state", null);
  } else {
    syncSliders();
    applyQ();
    showScenePose();
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
