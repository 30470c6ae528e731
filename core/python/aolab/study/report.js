/* report.html of `aolab compare`: draws the plots with plotly.js and opens a configuration's
 * images (docs/comparison.md, "report.html"). Written by aolab/study/report.py beside the
 * report as report_files/report-<hash>.js.
 *
 * The page holds, as inert JSON: per plot, a <script type="application/json" class="figure"
 * data-plot="ID"> with its plotly.js figure (a point's customdata is its results.csv key), and
 * one <script class="images"> with every scene's image files. Clicking a point, or a row of a
 * table, opens the viewer: the configuration's AO image and signed error map beside the
 * reference (a scene's point), or on every scene (a point of "All scenes"). Clicking a name
 * in a legend hides or shows it in the three plots of its section.
 */
(function () {
  'use strict';

  // No logo, no selection tools: a point is clicked, not selected.
  var CONFIG = {displaylogo: false, modeBarButtonsToRemove: ['select2d', 'lasso2d']};

  function readJson(el) {
    return el ? JSON.parse(el.textContent) : null;
  }

  var images = readJson(document.querySelector('script.images')) || {order: [], scenes: {}};

  // ---- the viewer ------------------------------------------------------------------------

  function element(tag, cls, text) {
    var e = document.createElement(tag);
    if (cls) e.className = cls;
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function figure(src, caption, size) {
    var f = element('figure', 'shot');
    var img = element('img');
    img.src = src;
    img.alt = caption;
    img.width = size[0];
    img.height = size[1];
    f.appendChild(img);
    f.appendChild(element('figcaption', '', caption));
    return f;
  }

  /* The scenes whose images show ``key`` ("scene/method/label"): its own scene, or for a
   * key of ALL every scene that has the configuration. */
  function shots(key) {
    var cut = key.indexOf('/');
    var scene = key.slice(0, cut), config = key.slice(cut + 1);
    var names = scene !== 'ALL' ? [scene] : images.order.filter(function (n) {
      return images.scenes[n].in_all;
    });
    var out = [];
    names.forEach(function (name) {
      var s = images.scenes[name];
      if (s && s.configs[config]) out.push({scene: name, files: s.configs[config], info: s});
    });
    return {scene: scene, config: config, found: out};
  }

  function openViewer(key, caption) {
    var viewer = document.getElementById('viewer');
    var body = viewer.querySelector('.viewer-body');
    body.textContent = '';
    var head = element('div', 'viewer-caption');
    if (caption) {   // the point's hover text: its first line, then the rest on one line
      var lines = caption.split('<br>').filter(function (l) { return l.indexOf('<i>') !== 0; });
      head.innerHTML = lines[0] + '<br>' + lines.slice(1).join(' · ');
    } else {
      head.textContent = key;
    }
    body.appendChild(head);
    var got = shots(key);
    if (!got.found.length) {
      // Nothing of this configuration: the nearest thing there is, the scene's image grid.
      body.appendChild(element('p', 'missing', 'No image of ' + got.config + (got.scene === 'ALL'
          ? ' on any scene.' : ' on ' + got.scene + ': its image grid is shown below the plots.')));
      viewer.hidden = false;
      return;
    }
    got.found.forEach(function (g) {
      var row = element('div', 'viewer-row');
      var title = g.scene + (g.info.note ? ' (' + g.info.note + ')' : '');
      row.appendChild(element('div', 'viewer-scene', title));
      var size = g.info.size;
      row.appendChild(figure(g.info.reference, 'Cycles 1024 spp reference', size));
      row.appendChild(figure(g.files[0], got.config + ': AO', size));
      row.appendChild(figure(g.files[1], 'signed error: blue lighter, red darker', size));
      body.appendChild(row);
    });
    viewer.hidden = false;
    viewer.querySelector('button').focus();
  }

  function closeViewer() {
    document.getElementById('viewer').hidden = true;
  }

  // ---- the plots ---------------------------------------------------------------------------

  /* A legend click hides or shows the trace of that name in every plot of gd's section; a
   * double click shows it alone (or, when it was alone, every trace). Returns false: plotly.js's
   * own toggle, of one plot, is not done. */
  var lastClick = {gd: null, name: null, time: 0};

  function legendClick(gd, ev) {
    var name = ev.data[ev.curveNumber].name;
    var now = Date.now();
    var double = lastClick.gd === gd && lastClick.name === name &&
        now - lastClick.time < gd._context.doubleClickDelay;
    lastClick = double ? {gd: null, name: null, time: 0} : {gd: gd, name: name, time: now};
    var alone = gd._fullData.every(function (t) {
      return t.name === name || t.visible !== true;
    });
    var hide = ev.fullData[ev.curveNumber].visible === true;
    var section = CSS.escape(gd.getAttribute('data-section'));
    var plots = document.querySelectorAll('div.plot[data-section="' + section + '"]');
    Array.prototype.forEach.call(plots, function (other) {
      if (!double) {
        var idx = [];
        other.data.forEach(function (t, i) { if (t.name === name) idx.push(i); });
        if (idx.length) Plotly.restyle(other, {visible: hide ? 'legendonly' : true}, idx);
        return;
      }
      Plotly.restyle(other, {visible: other.data.map(function (t) {
        return alone || t.name === name ? true : 'legendonly';
      })});
    });
    return false;
  }

  function draw() {
    var specs = document.querySelectorAll('script.figure');
    if (!specs.length) return Promise.resolve();
    if (!window.Plotly) return Promise.resolve();   // (the page's check says so)
    var drawn = Array.prototype.map.call(specs, function (spec) {
      var gd = document.getElementById(spec.getAttribute('data-plot'));
      var fig = readJson(spec);
      return Plotly.newPlot(gd, fig.data, fig.layout, CONFIG).then(function () {
        gd.on('plotly_click', function (ev) {
          var p = ev.points && ev.points[0];
          if (p && typeof p.customdata === 'string') openViewer(p.customdata, p.text);
        });
        gd.on('plotly_legendclick', function (ev) { return legendClick(gd, ev); });
      });
    });
    return Promise.all(drawn);
  }

  // ---- wiring ------------------------------------------------------------------------------

  document.addEventListener('keydown', function (ev) {
    if (ev.key === 'Escape') closeViewer();
  });
  var viewer = document.getElementById('viewer');
  if (viewer) {
    viewer.addEventListener('click', function (ev) {
      if (ev.target === viewer || ev.target.tagName === 'BUTTON') closeViewer();
    });
  }
  Array.prototype.forEach.call(document.querySelectorAll('tr[data-key]'), function (tr) {
    if (!shots(tr.getAttribute('data-key')).found.length) return;
    tr.classList.add('has-image');
    tr.title = (tr.title ? tr.title + '\n' : '') + 'click: image and error map';
    tr.addEventListener('click', function () { openViewer(tr.getAttribute('data-key')); });
  });
  window.aolabReport = {ready: draw(), open: openViewer, close: closeViewer};
})();
