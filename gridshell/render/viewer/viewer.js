// gridshell report viewer: the design bundle's surface, strips and joints in WebGL (three.js).
// Reads the scene written by gridshell/render/viewer/scene.py from the JSON script element
// #gridshell-scene of the page; no network, works from file://.
(function () {
  "use strict";
  var root = document.getElementById("gridshell-viewer");
  var dataEl = document.getElementById("gridshell-scene");
  var threeEl = document.getElementById("gridshell-three");
  if (!root || !dataEl) { return; }

  // the scene and three.js come gzip-compressed in base64 (render/viewer/page.py)
  function unpack(elem) {
    if (elem.type !== "application/gzip") { return Promise.resolve(elem.textContent); }
    if (typeof DecompressionStream === "undefined") {
      return Promise.reject(new Error("no DecompressionStream"));
    }
    var bin = atob(elem.textContent.trim()), u8 = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) { u8[i] = bin.charCodeAt(i); }
    var stream = new Blob([u8]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Response(stream).text();
  }
  Promise.all([unpack(dataEl), threeEl ? unpack(threeEl) : Promise.resolve(null)]).then(
    function (texts) {
      if (texts[1] !== null && typeof THREE === "undefined") {
        var lib = document.createElement("script");
        lib.textContent = texts[1];
        document.head.appendChild(lib);             // runs now: defines THREE
      }
      start(JSON.parse(texts[0]));
    },
    function () {
      var note = document.createElement("p");
      note.className = "gv-note";
      note.textContent = "This browser cannot unpack the 3D view (it needs " +
        "DecompressionStream: Chrome 80, Firefox 113, Safari 16.4 or later). " +
        "The pictures below show the design.";
      root.querySelector(".gv-view").appendChild(note);
    });

  function start(S) {

  function bytes(b64) {
    var bin = atob(b64), u8 = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) { u8[i] = bin.charCodeAt(i); }
    return u8.buffer;
  }
  function f32(b64) { return new Float32Array(bytes(b64)); }
  function u32(b64) { return new Uint32Array(bytes(b64)); }
  function el(tag, attrs, text) {
    var e = document.createElement(tag);
    for (var k in (attrs || {})) { e.setAttribute(k, attrs[k]); }
    if (text !== undefined) { e.textContent = text; }
    return e;
  }

  var view = root.querySelector(".gv-view");
  var panel = root.querySelector(".gv-panel");
  var probe = document.createElement("canvas");
  if (!window.WebGLRenderingContext || !(probe.getContext("webgl2") || probe.getContext("webgl"))) {
    view.appendChild(el("p", {"class": "gv-note"},
      "This browser has no WebGL: the 3D view is off. The pictures below show the design."));
    return;
  }

  // ---- geometry ------------------------------------------------------------------------
  var lo = S.bbox[0], hi = S.bbox[1];
  var centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  var diag = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  var FAMILY = {1: new THREE.Color(0.13, 0.42, 0.70), 3: new THREE.Color(0.86, 0.35, 0.12)};
  var RAMP = [[0.17, 0.48, 0.71], [0.45, 0.75, 0.85], [0.98, 0.93, 0.60], [0.99, 0.60, 0.30],
              [0.84, 0.10, 0.11]];
  var MODES = {
    family: {label: "family"},
    delta_a: {label: "Delta_a [%]", lo: 0, hi: 3, scalar: "delta_a",
              note: "Delta_a of the net-loops at each joint (paper 5.1); red: 3 % and more"},
    utilisation: {label: "stress utilisation", lo: 0, hi: 1, scalar: "utilisation",
                  note: "structure.json: stress / strength; red: 1 and more (fails)"}
  };

  var scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f5f7);
  var world = new THREE.Group();
  world.position.copy(centre).multiplyScalar(-1);
  scene.add(world);

  var surfGeo = new THREE.BufferGeometry();
  surfGeo.setAttribute("position", new THREE.BufferAttribute(f32(S.surface.V), 3));
  surfGeo.setIndex(new THREE.BufferAttribute(u32(S.surface.F), 1));
  surfGeo.computeVertexNormals();
  var surface = new THREE.Mesh(surfGeo, new THREE.MeshStandardMaterial({
    color: 0xc3c7ce, roughness: 0.9, metalness: 0.0, side: THREE.DoubleSide,
    transparent: true, opacity: 0.8, polygonOffset: true, polygonOffsetFactor: 2,
    polygonOffsetUnits: 2}));
  surface.renderOrder = 0;
  world.add(surface);

  // strip vertices: uint16 over their box (render/viewer/scene.py, quantized)
  var Q = S.strips.quant;
  function dequant(b64) {
    var u = new Uint16Array(bytes(b64)), out = new Float32Array(u.length);
    var sp = [0, 1, 2].map(function (c) { return (Q.hi[c] > Q.lo[c] ? Q.hi[c] - Q.lo[c] : 1) / Q.steps; });
    for (var i = 0; i < u.length; i++) { out[i] = Q.lo[i % 3] + u[i] * sp[i % 3]; }
    return out;
  }
  var stripPos = S.strips.V.map(dequant);
  // the faces of each lamella's solid depend on its number of samples k alone
  // (geometry/strips3d.py strip_solid_faces: vertex 4i + c is corner c of section i)
  function solidFaces() {
    var F = new Uint32Array(S.strips.nf * 3);
    S.lamellae.forEach(function (lam) {
      var k = lam.samples, v = lam.v0, f = 3 * lam.f0;
      for (var a = 0; a < 4; a++) {
        var b = (a + 1) % 4;
        for (var i = 0; i < k - 1; i++) {
          var p = v + 4 * i;
          F.set([p + a, p + b, p + 4 + b, p + a, p + 4 + b, p + 4 + a], f);
          f += 6;
        }
      }
      var last = v + 4 * (k - 1);
      F.set([v, v + 2, v + 1, v, v + 3, v + 2, last, last + 1, last + 2, last, last + 2, last + 3], f);
    });
    return F;
  }
  var stripIdx = S.strips.F ? u32(S.strips.F) : solidFaces();
  var nStripV = S.strips.nv;
  var posAttr = new THREE.BufferAttribute(new Float32Array(stripPos[0]), 3);
  posAttr.setUsage(THREE.DynamicDrawUsage);
  var colAttr = new THREE.BufferAttribute(new Float32Array(nStripV * 3), 3);
  var families = {};
  S.lamellae.forEach(function (L) {
    (families[L.family] = families[L.family] || []).push(L);
  });
  var stripMeshes = {};
  Object.keys(families).forEach(function (fam) {
    var idx = [];
    families[fam].forEach(function (L) {
      for (var i = L.f0 * 3; i < (L.f0 + L.nf) * 3; i++) { idx.push(stripIdx[i]); }
    });
    var g = new THREE.BufferGeometry();
    g.setAttribute("position", posAttr);
    g.setAttribute("color", colAttr);
    g.setIndex(new THREE.BufferAttribute(new Uint32Array(idx), 1));
    var m = new THREE.Mesh(g, new THREE.MeshStandardMaterial({
      vertexColors: true, flatShading: true, roughness: 0.6, metalness: 0.0,
      side: THREE.DoubleSide}));
    m.renderOrder = 1;
    stripMeshes[fam] = m;
    world.add(m);
  });

  var jointPos = S.joints.V.map(f32);
  var jointDa = f32(S.joints.delta_a);
  var nJ = S.joints.n;
  var joints = new THREE.InstancedMesh(new THREE.SphereGeometry(S.joints.radius, 12, 8),
    new THREE.MeshStandardMaterial({color: 0xffffff, roughness: 0.5}), Math.max(nJ, 1));
  joints.count = nJ;
  joints.renderOrder = 2;
  world.add(joints);

  // net-loops: two triangles per loop over the joints of the current state, coloured per loop
  var loopIdx = u32(S.loops.F), loopDa = f32(S.loops.delta_a), nL = S.loops.m;
  var loopGeo = new THREE.BufferGeometry();
  var loopPos = new THREE.BufferAttribute(new Float32Array(nL * 18), 3);
  var loopCol = new THREE.BufferAttribute(new Float32Array(nL * 18), 3);
  loopGeo.setAttribute("position", loopPos);
  loopGeo.setAttribute("color", loopCol);
  var loops = new THREE.Mesh(loopGeo, new THREE.MeshStandardMaterial({
    vertexColors: true, side: THREE.DoubleSide, roughness: 0.9, transparent: true,
    opacity: 0.85, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1}));
  loops.visible = false;
  world.add(loops);
  var TRI = [0, 1, 2, 0, 2, 3];

  scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 1.6));
  var camera = new THREE.PerspectiveCamera(35, 1, diag / 1000, diag * 20);
  camera.up.set(0, 0, 1);
  var lamp = new THREE.DirectionalLight(0xffffff, 1.4);
  lamp.position.set(0.3, 0.5, 1);
  camera.add(lamp);
  scene.add(camera);

  var canvas = el("canvas", {"class": "gv-canvas", "aria-label": "3D view of the gridshell"});
  view.appendChild(canvas);
  var renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true,
                                          preserveDrawingBuffer: true});
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  var controls = new THREE.OrbitControls(camera, canvas);
  controls.enableDamping = false;

  // the extent (diagonal) of the strips shown in a state: the home view frames that state
  function stateDiag(k) {
    var P = stripPos[k], a = [Infinity, Infinity, Infinity], b = [-Infinity, -Infinity, -Infinity];
    for (var i = 0; i < P.length; i++) {
      var c = i % 3;
      if (P[i] < a[c]) { a[c] = P[i]; }
      if (P[i] > b[c]) { b[c] = P[i]; }
    }
    return Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]) || diag;
  }

  function homeView() {
    var ext = new THREE.Vector3(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    // the state's diagonal over 0.75 of the view's height (wider views: of its width too)
    var fit = stateDiag(shownCentre) / Math.min(1, camera.aspect || 1);
    var d = 0.75 * fit / (2 * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)));
    var dir = new THREE.Vector3(ext.y >= ext.x ? 0.85 : 0.35, ext.y >= ext.x ? -0.35 : -0.85,
                                0.75).normalize();
    camera.position.copy(dir.multiplyScalar(d));
    var c = S.centres[shownCentre];
    var at = new THREE.Vector3(c[0], c[1], c[2]).sub(centre);
    camera.position.add(at);
    controls.target.copy(at);
    controls.update();
  }

  // ---- state, colours, visibility ------------------------------------------------------
  var state = 0, mode = "family", shownCentre = 0;
  var show = {surface: true, f1: true, f3: true, joints: true, loops: false};
  var dummy = new THREE.Object3D();

  function ramp(v, m) {
    if (!(v === v)) { return [0.6, 0.6, 0.6]; }  // NaN: not measured
    var x = Math.min(Math.max((v - m.lo) / (m.hi - m.lo), 0), 1) * (RAMP.length - 1);
    var i = Math.min(Math.floor(x), RAMP.length - 2), f = x - i;
    return [0, 1, 2].map(function (c) { return RAMP[i][c] * (1 - f) + RAMP[i + 1][c] * f; });
  }

  function colour() {
    var m = MODES[mode], c = colAttr.array;
    var values = m.scalar ? f32(S.scalars[m.scalar]) : null;
    S.lamellae.forEach(function (L, li) {
      var off = 0;
      for (var k = 0; k < li; k++) { off += S.lamellae[k].samples; }
      for (var p = 0; p < L.samples; p++) {
        var rgb = values ? ramp(values[off + p], m) : FAMILY[L.family].toArray();
        for (var q = 0; q < 4; q++) {   // the 4 corners of the section at this sample
          var v = L.v0 + 4 * p + q;
          c[3 * v] = rgb[0]; c[3 * v + 1] = rgb[1]; c[3 * v + 2] = rgb[2];
        }
      }
    });
    colAttr.needsUpdate = true;
    var jc = new THREE.Color();
    for (var j = 0; j < nJ; j++) {
      if (mode === "delta_a") { jc.setRGB.apply(jc, ramp(jointDa[j], m)); }
      else { jc.setRGB(0.16, 0.17, 0.2); }
      joints.setColorAt(j, jc);
    }
    if (joints.instanceColor) { joints.instanceColor.needsUpdate = true; }
    var lc = loopCol.array, da = MODES.delta_a;
    for (var l = 0; l < nL; l++) {
      var rgb = mode === "family" ? [0.55, 0.74, 0.55] : ramp(loopDa[l], da);
      for (var q = 0; q < 6; q++) { lc.set(rgb, 18 * l + 3 * q); }
    }
    loopCol.needsUpdate = true;
    legend(m);
  }

  function setState(k) {
    state = Math.max(0, Math.min(S.states.length - 1, k | 0));
    posAttr.array.set(stripPos[state]);
    posAttr.needsUpdate = true;
    Object.keys(stripMeshes).forEach(function (f) {
      stripMeshes[f].geometry.computeBoundingSphere();
    });
    var J = jointPos[state];
    for (var j = 0; j < nJ; j++) {
      dummy.position.set(J[3 * j], J[3 * j + 1], J[3 * j + 2]);
      dummy.updateMatrix();
      joints.setMatrixAt(j, dummy.matrix);
    }
    joints.instanceMatrix.needsUpdate = true;
    var lp = loopPos.array;
    for (var l = 0; l < nL; l++) {
      for (var q = 0; q < 6; q++) {
        var jj = loopIdx[4 * l + TRI[q]];
        lp[18 * l + 3 * q] = J[3 * jj]; lp[18 * l + 3 * q + 1] = J[3 * jj + 1];
        lp[18 * l + 3 * q + 2] = J[3 * jj + 2];
      }
    }
    loopPos.needsUpdate = true;
    loopGeo.computeVertexNormals();
    loopGeo.computeBoundingSphere();
    joints.computeBoundingSphere();
    // the view follows the sequence: the camera moves with the centre of the state
    var c0 = S.centres[shownCentre], c1 = S.centres[state];
    var shift = new THREE.Vector3(c1[0] - c0[0], c1[1] - c0[1], c1[2] - c0[2]);
    camera.position.add(shift);
    controls.target.add(shift);
    controls.update();
    shownCentre = state;
    stateLabel.textContent = S.states[state];
    visibility();
  }

  function visibility() {
    surface.visible = show.surface && state === 0;
    if (stripMeshes[1]) { stripMeshes[1].visible = show.f1; }
    if (stripMeshes[3]) { stripMeshes[3].visible = show.f3; }
    joints.visible = show.joints;
    loops.visible = show.loops;
    render();
  }

  var pending = false;
  function render() {
    var w = view.clientWidth || 800, h = view.clientHeight || 520;
    if (canvas.width !== Math.round(w * renderer.getPixelRatio()) ||
        canvas.height !== Math.round(h * renderer.getPixelRatio())) {
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
    }
    renderer.render(scene, camera);
  }
  function later() {
    if (!pending) {
      pending = true;
      requestAnimationFrame(function () { pending = false; render(); });
    }
  }

  // ---- the panel -----------------------------------------------------------------------
  function toggle(key, label, title) {
    var lab = el("label", {"class": "gv-toggle", title: title || ""});
    var box = el("input", {type: "checkbox", "data-layer": key});
    box.checked = show[key];
    box.addEventListener("change", function () { show[key] = box.checked; visibility(); });
    lab.appendChild(box);
    lab.appendChild(document.createTextNode(" " + label));
    return lab;
  }
  var layers = el("div", {"class": "gv-row"});
  layers.appendChild(el("span", {"class": "gv-key"}, "show"));
  layers.appendChild(toggle("surface", "surface", "the designed surface (deployed state only)"));
  var n1 = (families[1] || []).length, n3 = (families[3] || []).length;
  layers.appendChild(toggle("f1", "family C1 (" + n1 + ")"));
  layers.appendChild(toggle("f3", "family C3 (" + n3 + ")"));
  layers.appendChild(toggle("joints", "joints (" + nJ + ")"));
  layers.appendChild(toggle("loops", "net-loops (" + nL + ")",
                            "the net's quads between the joints, coloured by Delta_a"));
  panel.appendChild(layers);

  var colours = el("div", {"class": "gv-row"});
  colours.appendChild(el("span", {"class": "gv-key"}, "colour"));
  var select = el("select", {"data-control": "colour"});
  Object.keys(MODES).forEach(function (k) {
    if (k === "utilisation" && !S.scalars.utilisation) { return; }
    select.appendChild(el("option", {value: k}, MODES[k].label));
  });
  select.addEventListener("change", function () { mode = select.value; colour(); render(); });
  colours.appendChild(select);
  var legendBox = el("span", {"class": "gv-legend"});
  colours.appendChild(legendBox);
  panel.appendChild(colours);
  if (!S.scalars.utilisation) {
    panel.appendChild(el("div", {"class": "gv-hint"},
      "Stress utilisation: run 'gridshell check DIR' and re-render the report."));
  }

  function legend(m) {
    legendBox.textContent = "";
    if (!m.scalar) {
      [1, 3].forEach(function (f) {
        if (!families[f]) { return; }
        var sw = el("i", {"class": "gv-swatch"});
        sw.style.background = "#" + FAMILY[f].getHexString();
        legendBox.appendChild(sw);
        legendBox.appendChild(document.createTextNode(" C" + f + " "));
      });
      return;
    }
    var stops = RAMP.map(function (c) {
      return "rgb(" + c.map(function (x) { return Math.round(255 * x); }).join(",") + ")";
    });
    var bar = el("i", {"class": "gv-bar"});
    bar.style.background = "linear-gradient(90deg," + stops.join(",") + ")";
    legendBox.appendChild(document.createTextNode(m.lo + " "));
    legendBox.appendChild(bar);
    var top = m.scalar === "delta_a" ? S.delta_a.max : S.max_utilisation;
    legendBox.appendChild(document.createTextNode(" " + m.hi + (m.scalar === "delta_a" ? " %" : "")
      + " \u2014 " + m.note + (top === null || top === undefined ? "" :
                               "; largest " + top.toPrecision(3))));
  }

  var seq = el("div", {"class": "gv-row"});
  seq.appendChild(el("span", {"class": "gv-key"}, "alignment"));
  var slider = el("input", {type: "range", min: "0", max: String(S.states.length - 1),
                            step: "1", value: "0", "data-control": "state",
                            "aria-label": "state of the alignment sequence"});
  slider.addEventListener("input", function () { setState(+slider.value); });
  seq.appendChild(slider);
  var stateLabel = el("span", {"class": "gv-state"});
  seq.appendChild(stateLabel);
  var reset = el("button", {type: "button"}, "reset view");
  reset.addEventListener("click", function () { homeView(); render(); });
  seq.appendChild(reset);
  panel.appendChild(seq);
  panel.appendChild(el("div", {"class": "gv-hint"},
    "Strips " + S.section.text + ", " + (S.tangent ? "tangent to" : "standing on") +
    " the surface. Drag to orbit, wheel to zoom, right-drag to pan."));

  controls.addEventListener("change", later);
  if (window.ResizeObserver) { new ResizeObserver(later).observe(view); }
  else { window.addEventListener("resize", later); }
  homeView();
  colour();
  setState(0);
  root.setAttribute("data-ready", "1");
  window.gridshellViewer = {setState: setState, render: render,
                            states: S.states.length, scene: S};
  }
})();
