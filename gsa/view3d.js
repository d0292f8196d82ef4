// gsa's interactive 3-D view (gsa/view3d.hpp): reads the JSON of <script id="gsa-view-data">
// and draws the fitted surfaces, the marks and the principal strain arrows with three.js.
// Mouse: left drag rotates, right drag (or shift + drag) pans, wheel zooms; a click reads
// the values at the point. URL hash options (also for tests): #rotate=DEG (turn the view
// about the vertical axis), field=KEY, state=undeformed, marks=0|1, arrows=0|1.
(function () {
  'use strict';
  var root = document.getElementById('gsa-view');
  if (!root) return;
  var bar = root.querySelector('.gv-bar');
  var stage = root.querySelector('.gv-stage');
  var foot = root.querySelector('.gv-foot');

  function fail(message) {
    root.dataset.state = 'error';
    root.dataset.error = message;
    if (window.console) console.error('gsa 3-D view: ' + message);
    var p = document.createElement('p');
    p.className = 'gv-msg';
    p.textContent = '3-D view unavailable: ' + message;
    stage.appendChild(p);
  }

  function decode(text, Type) {
    var bin = atob(text);
    var bytes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }

  // Viridis (the pictures' colour map), 11 stops.
  var VIRIDIS = [
    [0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.530], [0.207, 0.372, 0.553],
    [0.164, 0.471, 0.558], [0.128, 0.567, 0.551], [0.135, 0.659, 0.518], [0.267, 0.749, 0.441],
    [0.478, 0.821, 0.318], [0.741, 0.873, 0.150], [0.993, 0.906, 0.144]];
  var CATEGORY = [
    [0.12, 0.47, 0.71], [1.0, 0.5, 0.05], [0.17, 0.63, 0.17], [0.84, 0.15, 0.16], [0.58, 0.4, 0.74],
    [0.55, 0.34, 0.29], [0.89, 0.47, 0.76], [0.5, 0.5, 0.5], [0.74, 0.74, 0.13], [0.09, 0.75, 0.81]];
  var NO_VALUE = [0.78, 0.78, 0.78];
  var DENSE_MARKS = 3000;  // above: marks hidden at first and drawn smaller (they would cover the part)

  function viridis(t) {
    t = Math.min(1, Math.max(0, t)) * (VIRIDIS.length - 1);
    var i = Math.min(VIRIDIS.length - 2, Math.floor(t)), a = t - i;
    var p = VIRIDIS[i], q = VIRIDIS[i + 1];
    return [p[0] + a * (q[0] - p[0]), p[1] + a * (q[1] - p[1]), p[2] + a * (q[2] - p[2])];
  }

  function fmt(v) {
    if (v === null || v === undefined || !isFinite(v)) return '\u2013';
    var a = Math.abs(v);
    if (a !== 0 && (a < 1e-3 || a >= 1e6)) return v.toExponential(3);
    return String(Number(v.toPrecision(4)));
  }

  // Colour bar labels: enough decimals to tell the ticks apart.
  function tick(v, lo, hi) {
    if (v === null || !isFinite(v)) return '\u2013';
    var step = (hi - lo) / 4, a = Math.max(Math.abs(lo), Math.abs(hi));
    if (!(step > 0) || a >= 1e6 || a < 1e-4) return fmt(v);
    var decimals = Math.max(0, Math.min(10, Math.ceil(-Math.log10(step)) + 1));
    var text = v.toFixed(decimals);
    return /^-0\.?0*$/.test(text) ? text.slice(1) : text;  // no "-0.0"

  }

  function hashOptions() {
    var o = {};
    (location.hash || '').replace(/^#/, '').split(/[&;]/).forEach(function (kv) {
      if (!kv) return;
      var k = kv.split('=');
      o[decodeURIComponent(k[0])] = k.length > 1 ? decodeURIComponent(k[1]) : '1';
    });
    return o;
  }

  function setAttr(geometry, name, attribute) {
    if (geometry.setAttribute) geometry.setAttribute(name, attribute);
    else geometry.addAttribute(name, attribute);
  }

  function main() {
    if (typeof THREE === 'undefined') throw new Error('three.js did not load');
    var D = JSON.parse(document.getElementById('gsa-view-data').textContent);
    var S = D.surface, G = D.glyphs, M = D.marks || null;
    var VC = THREE.VertexColors !== undefined ? THREE.VertexColors : true;

    // Surface data.
    var posU = decode(S.pos_u, Float32Array), posD = decode(S.pos_d, Float32Array);
    var index = decode(S.index, Uint32Array);
    var nv = S.n_vertices;
    var fields = [];  // {key, label, unit, range, values, where: 'surface'|'marks', categories}
    S.fields.forEach(function (f) {
      fields.push({key: f.key, label: f.label, unit: f.unit, range: f.range, dataRange: f.data_range || null,
                   values: decode(f.data, Float32Array), where: 'surface'});
    });
    var surfaceKeys = {};
    S.fields.forEach(function (f) { surfaceKeys[f.key] = true; });
    var markPosU = null, markPosD = null, markCols = [];
    if (M && M.n > 0) {
      markPosU = decode(M.pos_u, Float32Array);
      markPosD = decode(M.pos_d, Float32Array);
      M.columns.forEach(function (c) {
        var f = {key: c.key, label: c.label, unit: c.unit, range: c.range || null, dataRange: c.data_range || null,
                 values: decode(c.data, Float32Array), where: 'marks', categories: c.categories || null};
        markCols.push(f);
        fields.push(f);
      });
    }

    // Renderer, scene, camera, lights.
    var canvas = document.createElement('canvas');
    canvas.className = 'gv-gl';
    stage.appendChild(canvas);
    var renderer;
    try {
      renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true, preserveDrawingBuffer: true});
    } catch (e) {
      throw new Error('WebGL is not available in this browser (' + (e.message || e) + '); the pictures show the ' +
                      'same fields');
    }
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setClearColor(0xffffff, 1);
    var scene = new THREE.Scene();
    var camera = new THREE.PerspectiveCamera(30, 1, 0.1, 1000);
    camera.up.set(0, 0, 1);
    scene.add(camera);
    scene.add(new THREE.AmbientLight(0xffffff, 0.5));
    var light = new THREE.DirectionalLight(0xffffff, 0.6);
    light.position.set(0.3, 0.6, 1);
    var lightTarget = new THREE.Object3D();
    lightTarget.position.set(0, 0, -1);
    camera.add(light);
    camera.add(lightTarget);
    light.target = lightTarget;

    var geometry = new THREE.BufferGeometry();
    var position = new THREE.BufferAttribute(new Float32Array(posD), 3);
    var colour = new THREE.BufferAttribute(new Float32Array(nv * 3), 3);
    setAttr(geometry, 'position', position);
    setAttr(geometry, 'color', colour);
    geometry.setIndex(new THREE.BufferAttribute(index, 1));
    geometry.computeVertexNormals();
    geometry.computeBoundingSphere();
    var material = new THREE.MeshLambertMaterial({vertexColors: VC, side: THREE.DoubleSide, polygonOffset: true,
                                                  polygonOffsetFactor: 6, polygonOffsetUnits: 6});
    var mesh = new THREE.Mesh(geometry, material);
    scene.add(mesh);

    var markGeometry = null, markPoints = null, markPosition = null, markColour = null;
    if (markPosU) {
      markGeometry = new THREE.BufferGeometry();
      markPosition = new THREE.BufferAttribute(new Float32Array(markPosD), 3);
      markColour = new THREE.BufferAttribute(new Float32Array(M.n * 3), 3);
      setAttr(markGeometry, 'position', markPosition);
      setAttr(markGeometry, 'color', markColour);
      markPoints = new THREE.Points(markGeometry, new THREE.PointsMaterial({size: 5, sizeAttenuation: false,
                                                                           vertexColors: VC}));
      scene.add(markPoints);
    }
    var glyphs = null;
    var picked = new THREE.Points(new THREE.BufferGeometry(), new THREE.PointsMaterial({size: 11,
      sizeAttenuation: false, color: 0xff00ff, depthTest: false}));
    setAttr(picked.geometry, 'position', new THREE.BufferAttribute(new Float32Array(3), 3));
    picked.visible = false;
    picked.renderOrder = 10;
    scene.add(picked);

    var controls = new THREE.OrbitControls(camera, canvas);
    controls.screenSpacePanning = true;
    controls.addEventListener('change', render);

    // State and the controls bar.
    var opts = hashOptions();
    var state = {deformed: opts.state !== 'undeformed', field: fields.length ? fields[0] : null,
                 marks: opts.marks ? opts.marks !== '0' : !!M && M.n <= DENSE_MARKS, arrows: opts.arrows === '1'};
    // field=KEY: the surface field KEY, else the strains.csv column KEY; field=marks:KEY: the column.
    if (opts.field) {
      var want = opts.field.replace(/^marks:/, ''), onMarks = opts.field.indexOf('marks:') === 0;
      var found = fields.filter(function (f) { return f.key === want && (!onMarks || f.where === 'marks'); });
      if (found.length) state.field = found[0];
    }

    function label(text, el) {
      var l = document.createElement('label');
      l.appendChild(document.createTextNode(text));
      l.appendChild(el);
      bar.appendChild(l);
      return el;
    }
    var select = document.createElement('select');
    [['surface', 'On the fitted surface'], ['marks', 'At the marks (' + (M ? M.source : '') + ')']].forEach(
        function (g) {
          var group = document.createElement('optgroup');
          group.label = g[1];
          fields.forEach(function (f, k) {
            if (f.where !== g[0]) return;
            var o = document.createElement('option');
            o.value = String(k);
            o.textContent = f.label + (f.unit && f.unit !== '-' ? ' (' + f.unit + ')' : '');
            if (f === state.field) o.selected = true;
            group.appendChild(o);
          });
          if (group.children.length) select.appendChild(group);
        });
    label('Colour: ', select).addEventListener('change', function () {
      state.field = fields[Number(select.value)];
      update();
    });
    var shape = document.createElement('select');
    shape.innerHTML = '<option value="d">deformed (formed part)</option><option value="u">undeformed (blank)</option>';
    shape.value = state.deformed ? 'd' : 'u';
    label('Surface: ', shape).addEventListener('change', function () {
      state.deformed = shape.value === 'd';
      setShape();
      fitView(true);
      update();
    });
    function checkbox(text, on, change) {
      var c = document.createElement('input');
      c.type = 'checkbox';
      c.checked = on;
      var l = document.createElement('label');
      l.appendChild(c);
      l.appendChild(document.createTextNode(' ' + text));
      bar.appendChild(l);
      c.addEventListener('change', function () { change(c.checked); });
      return c;
    }
    if (markPoints) checkbox('marks', state.marks, function (v) { state.marks = v; update(); });
    if (G && G.n > 0) checkbox('principal strain arrows', state.arrows, function (v) { state.arrows = v; update(); });
    var reset = document.createElement('button');
    reset.type = 'button';
    reset.textContent = 'Fit view';
    reset.addEventListener('click', function () { fitView(false); render(); });
    bar.appendChild(reset);

    var legend = document.createElement('div');
    legend.className = 'gv-legend';
    stage.appendChild(legend);
    var info = document.createElement('div');
    info.className = 'gv-info';
    stage.appendChild(info);

    function setShape() {
      position.array.set(state.deformed ? posD : posU);
      position.needsUpdate = true;
      geometry.computeVertexNormals();
      geometry.computeBoundingSphere();
      if (markPosition) {
        markPosition.array.set(state.deformed ? markPosD : markPosU);
        markPosition.needsUpdate = true;
        markGeometry.computeBoundingSphere();
      }
      picked.visible = false;
      info.style.display = 'none';
    }

    function colourOf(f, v) {
      if (!isFinite(v)) return NO_VALUE;
      if (f.categories) return CATEGORY[Math.round(v) % CATEGORY.length];
      var lo = f.range && f.range[0] !== null ? f.range[0] : 0, hi = f.range && f.range[1] !== null ? f.range[1] : 1;
      return viridis(hi > lo ? (v - lo) / (hi - lo) : 0.5);
    }

    function paint() {
      var f = state.field, c = colour.array, k, rgb;
      for (k = 0; k < nv; ++k) {
        rgb = f && f.where === 'surface' ? colourOf(f, f.values[k]) : [0.86, 0.86, 0.86];
        c[3 * k] = rgb[0]; c[3 * k + 1] = rgb[1]; c[3 * k + 2] = rgb[2];
      }
      colour.needsUpdate = true;
      if (markPoints) {
        var onMarks = f && f.where === 'marks';
        var m = markColour.array;
        for (k = 0; k < M.n; ++k) {
          rgb = onMarks ? colourOf(f, f.values[k]) : [0.1, 0.1, 0.1];
          m[3 * k] = rgb[0]; m[3 * k + 1] = rgb[1]; m[3 * k + 2] = rgb[2];
        }
        markColour.needsUpdate = true;
        var dense = M.n > DENSE_MARKS;
        markPoints.material.size = onMarks ? (dense ? 4 : 9) : (dense ? 2 : 4);
        markPoints.visible = state.marks || onMarks;
      }
    }

    // Glyph spacing from the surface area per arrow site; the longest arrow spans 0.9 of it.
    var arrowScale = 0, arrowMax = 0;
    function surfaceArea(p) {
      var a = 0, v0 = new THREE.Vector3(), v1 = new THREE.Vector3(), v2 = new THREE.Vector3();
      for (var t = 0; t < index.length; t += 3) {
        v0.fromArray(p, 3 * index[t]); v1.fromArray(p, 3 * index[t + 1]); v2.fromArray(p, 3 * index[t + 2]);
        a += v1.sub(v0).cross(v2.sub(v0)).length() / 2;
      }
      return a;
    }
    function buildArrows() {
      if (glyphs) { scene.remove(glyphs); glyphs.geometry.dispose(); glyphs = null; }
      if (!state.arrows || !G || G.n === 0) return;
      var P = decode(state.deformed ? G.pos_d : G.pos_u, Float32Array);
      var dir = [decode(state.deformed ? G.dir1_d : G.dir1_u, Float32Array),
                 decode(state.deformed ? G.dir2_d : G.dir2_u, Float32Array)];
      var value = [decode(G.major, Float32Array), decode(G.minor, Float32Array)];
      var k, w;
      arrowMax = 0;
      for (k = 0; k < G.n; ++k)
        for (w = 0; w < 2; ++w) if (isFinite(value[w][k])) arrowMax = Math.max(arrowMax, Math.abs(value[w][k]));
      var spacing = Math.sqrt(surfaceArea(state.deformed ? posD : posU) / G.n);
      arrowScale = arrowMax > 0 ? 0.9 * spacing / arrowMax : 0;
      var xyz = [], rgb = [];
      var p = new THREE.Vector3(), d = new THREE.Vector3(), o = new THREE.Vector3();
      function seg(a, b, c) { xyz.push(a.x, a.y, a.z, b.x, b.y, b.z); rgb.push(c[0], c[1], c[2], c[0], c[1], c[2]); }
      for (k = 0; k < G.n; ++k) {
        p.fromArray(P, 3 * k);
        for (w = 0; w < 2; ++w) {
          var e = value[w][k];
          d.fromArray(dir[w], 3 * k);
          o.fromArray(dir[1 - w], 3 * k);
          if (!isFinite(e) || !isFinite(d.x) || !isFinite(o.x) || arrowScale === 0) continue;
          var half = 0.5 * arrowScale * Math.abs(e), head = Math.min(0.35 * half, 0.12 * spacing);
          var c = e >= 0 ? [0.8, 0.1, 0.1] : [0.1, 0.25, 0.85];
          for (var s = -1; s <= 1; s += 2) {
            var tip = p.clone().addScaledVector(d, s * half);
            seg(p, tip, c);
            // Tension: heads point out; compression: in (their wings outside the tip).
            var back = tip.clone().addScaledVector(d, (e >= 0 ? -s : s) * head);
            seg(tip, back.clone().addScaledVector(o, 0.5 * head), c);
            seg(tip, back.clone().addScaledVector(o, -0.5 * head), c);
          }
        }
      }
      var g = new THREE.BufferGeometry();
      setAttr(g, 'position', new THREE.BufferAttribute(new Float32Array(xyz), 3));
      setAttr(g, 'color', new THREE.BufferAttribute(new Float32Array(rgb), 3));
      glyphs = new THREE.LineSegments(g, new THREE.LineBasicMaterial({vertexColors: VC}));
      scene.add(glyphs);
    }

    function drawLegend() {
      var f = state.field;
      legend.innerHTML = '';
      if (!f) return;
      var title = document.createElement('div');
      title.style.fontWeight = '600';
      title.textContent = f.label + (f.unit ? ' (' + (f.unit === '-' ? 'dimensionless' : f.unit) + ')' : '');
      legend.appendChild(title);
      if (f.where === 'marks') {
        var sub = document.createElement('div');
        sub.textContent = 'at the marks';
        legend.appendChild(sub);
      }
      if (f.categories) {
        f.categories.forEach(function (name, k) {
          var row = document.createElement('div');
          var sw = document.createElement('span');
          var c = CATEGORY[k % CATEGORY.length];
          sw.style.cssText = 'display:inline-block;width:12px;height:12px;margin-right:6px;background:rgb(' +
              Math.round(255 * c[0]) + ',' + Math.round(255 * c[1]) + ',' + Math.round(255 * c[2]) + ')';
          row.appendChild(sw);
          row.appendChild(document.createTextNode(name));
          legend.appendChild(row);
        });
      } else {
        var box = document.createElement('div');
        box.style.cssText = 'display:flex;gap:6px;margin-top:4px';
        var bar2 = document.createElement('canvas');
        bar2.width = 18;
        bar2.height = 200;
        var g = bar2.getContext('2d');
        for (var y = 0; y < 200; ++y) {
          var c = viridis(1 - y / 199);
          g.fillStyle = 'rgb(' + Math.round(255 * c[0]) + ',' + Math.round(255 * c[1]) + ',' + Math.round(255 * c[2]) + ')';
          g.fillRect(0, y, 18, 1);
        }
        box.appendChild(bar2);
        var ticks = document.createElement('div');
        ticks.className = 'gv-ticks';
        var lo = f.range ? f.range[0] : null, hi = f.range ? f.range[1] : null;
        var values = lo === null || hi === null ? [null] : lo === hi ? [lo]
            : [hi, 0.75 * hi + 0.25 * lo, 0.5 * (lo + hi), 0.25 * hi + 0.75 * lo, lo];
        values.forEach(function (v) {
          var t = document.createElement('div');
          t.textContent = values.length === 1 ? 'constant: ' + fmt(v) : tick(v, lo, hi);
          ticks.appendChild(t);
        });
        box.appendChild(ticks);
        legend.appendChild(box);
        // A nearly uniform field: the bar is widened to the smallest range worth colouring
        // (as in the PNG plots), so say what the values span.
        var d = f.dataRange;
        if (d && d[0] !== null && lo !== null && (d[0] > lo || d[1] < hi)) {
          var u = document.createElement('div');
          u.className = 'gv-uniform';
          var a = fmt(d[0]), b = fmt(d[1]);
          u.textContent = (a === b ? 'uniform: ' + a : 'nearly uniform: ' + a + ' to ' + b) +
              (f.unit && f.unit !== '-' ? ' ' + f.unit : '');
          legend.appendChild(u);
        }
      }
      if (state.arrows && arrowScale > 0) {
        var a = document.createElement('div');
        a.style.marginTop = '4px';
        a.innerHTML = '<span style="color:#c11">tension</span> / <span style="color:#24d">compression</span> ' +
            'arrows: longest = ' + fmt(arrowMax) + ' (' + D.measure + ' strain)';
        legend.appendChild(a);
      }
    }

    function render() { renderer.render(scene, camera); }

    function update() {
      paint();
      buildArrows();
      drawLegend();
      render();
    }

    // The whole part in view; keepDirection: seen from the same side (after a switch of surface).
    function fitView(keepDirection) {
      var s = geometry.boundingSphere;
      var r = Math.max(s.radius, 1e-9);
      var dist = r / Math.sin(camera.fov * Math.PI / 360) * 1.05;
      var dir = keepDirection ? camera.position.clone().sub(controls.target).normalize()
                              : new THREE.Vector3(0.45, -0.8, 0.75).normalize();
      controls.target.copy(s.center);
      camera.position.copy(s.center).addScaledVector(dir, dist);
      camera.near = dist / 100;
      camera.far = dist * 100;
      camera.updateProjectionMatrix();
      controls.update();
    }

    function resize() {
      var w = Math.max(1, stage.clientWidth), h = Math.max(1, stage.clientHeight);
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
      render();
    }

    // A click (not a drag) reads the values at the point and at the nearest mark.
    var down = null;
    canvas.addEventListener('pointerdown', function (e) { down = [e.clientX, e.clientY]; });
    canvas.addEventListener('pointerup', function (e) {
      if (!down || Math.abs(e.clientX - down[0]) + Math.abs(e.clientY - down[1]) > 4) return;
      pick(e.clientX, e.clientY);
    });
    var raycaster = new THREE.Raycaster();
    function row(table, key, value) {
      var tr = document.createElement('tr'), th = document.createElement('th'), td = document.createElement('td');
      th.textContent = key;
      td.textContent = value;
      tr.appendChild(th);
      tr.appendChild(td);
      table.appendChild(tr);
    }
    function pick(x, y) {
      var rect = canvas.getBoundingClientRect();
      var ndc = new THREE.Vector2((x - rect.left) / rect.width * 2 - 1, -(y - rect.top) / rect.height * 2 + 1);
      raycaster.setFromCamera(ndc, camera);
      var hit = raycaster.intersectObject(mesh)[0];
      info.innerHTML = '';
      if (!hit) {
        picked.visible = false;
        info.style.display = 'none';
        render();
        return;
      }
      var P = position.array, f3 = hit.face;
      var A = new THREE.Vector3().fromArray(P, 3 * f3.a), B = new THREE.Vector3().fromArray(P, 3 * f3.b),
          C = new THREE.Vector3().fromArray(P, 3 * f3.c);
      var bary = THREE.Triangle.getBarycoord(hit.point, A, B, C, new THREE.Vector3());
      picked.geometry.attributes.position.array.set([hit.point.x, hit.point.y, hit.point.z]);
      picked.geometry.attributes.position.needsUpdate = true;
      picked.geometry.computeBoundingSphere();
      picked.visible = true;
      var h = document.createElement('b');
      h.textContent = 'Surface at (' + fmt(hit.point.x) + ', ' + fmt(hit.point.y) + ', ' + fmt(hit.point.z) + ') ' +
          D.units + (state.deformed ? ', formed part' : ', blank');
      info.appendChild(h);
      var t = document.createElement('table');
      fields.forEach(function (f) {
        if (f.where !== 'surface') return;
        var v = bary.x * f.values[f3.a] + bary.y * f.values[f3.b] + bary.z * f.values[f3.c];
        row(t, f.label, fmt(v) + (f.unit && f.unit !== '-' ? ' ' + f.unit : ''));
      });
      info.appendChild(t);
      if (markPosU) {
        var MP = state.deformed ? markPosD : markPosU, best = -1, bestD = Infinity;
        for (var k = 0; k < M.n; ++k) {
          var dx = MP[3 * k] - hit.point.x, dy = MP[3 * k + 1] - hit.point.y, dz = MP[3 * k + 2] - hit.point.z;
          var dd = dx * dx + dy * dy + dz * dz;
          if (dd < bestD) { bestD = dd; best = k; }
        }
        if (best >= 0) {
          var hm = document.createElement('b');
          hm.textContent = 'Nearest mark ' + M.ids[best] + ', ' + fmt(Math.sqrt(bestD)) + ' ' + D.units + ' away';
          info.appendChild(hm);
          // The strains, status and assessment first; the other columns (directions, fit
          // positions, residuals) folded away, so the panel stays short.
          var tm = document.createElement('table'), more = document.createElement('table'), nMore = 0;
          markCols.forEach(function (f) {
            var v = f.values[best];
            var main = surfaceKeys[f.key] || /^(status|zone|flag|flc_margin|mid_major|mid_minor|thickness_)/.test(f.key);
            if (!main) ++nMore;
            row(main ? tm : more, f.label, f.categories ? (isFinite(v) ? f.categories[Math.round(v)] : '\u2013')
                                                        : fmt(v) + (f.unit && f.unit !== '-' ? ' ' + f.unit : ''));
          });
          info.appendChild(tm);
          if (nMore > 0) {
            var det = document.createElement('details'), sum = document.createElement('summary');
            sum.textContent = nMore + ' more values of this mark';
            det.appendChild(sum);
            det.appendChild(more);
            info.appendChild(det);
          }
        }
      }
      info.style.display = 'block';
      render();
    }

    var notes = ['Drag to rotate, right-drag or shift-drag to pan, wheel to zoom; click the part to read its values.',
                 S.n_triangles + ' triangles (' + S.quads_per_element_side + ' x ' + S.quads_per_element_side +
                 ' quads per element' + (S.quads_per_element_side < S.tessellation_per_element_side
                     ? ', decimated from ' + S.tessellation_per_element_side + ' x ' +
                       S.tessellation_per_element_side + ' to keep the page small' : '') + ')'];
    if (M) {
      notes.push(M.n + ' marks' + (M.unplaced ? ' (' + M.unplaced + ' not on the surfaces, not drawn)' : ''));
      if (M.left_out && M.left_out.length)
        notes.push('columns of ' + M.source + ' left out to keep the page small: ' + M.left_out.join(', '));
    }
    notes.push('Strains in ' + D.measure + ' measure; lengths in ' + D.units + '. Drawn with ' + D.library + '.');
    foot.textContent = notes.join(' \u00b7 ');

    setShape();
    fitView(false);
    if (window.ResizeObserver) new ResizeObserver(resize).observe(stage);
    else window.addEventListener('resize', resize);
    resize();
    update();
    // For scripted checks (tests/gsa/view3d_browser.py): turn the view, read the state.
    window.gsaView = {
      rotate: function (deg) {
        var off = camera.position.clone().sub(controls.target);
        off.applyAxisAngle(new THREE.Vector3(0, 0, 1), deg * Math.PI / 180);
        camera.position.copy(controls.target).add(off);
        controls.update();
        render();
      },
      state: state
    };
    if (opts.rotate) window.gsaView.rotate(Number(opts.rotate) || 0);
    root.dataset.state = 'ready';
    root.dataset.triangles = String(S.n_triangles);
  }

  try {
    main();
  } catch (e) {
    fail(e && e.message ? e.message : String(e));
  }
})();
