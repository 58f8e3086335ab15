// ssm compare's interactive viewer: every technique and the ground truth in
// one pixel-exact frame. Works from disk with no network and no build step:
// the visibility values come from viewer-data.js (a <script>, which file://
// pages may load, unlike canvas reads of their own images), the shaded and
// FLIP images are drawn, never read back.
//
// Keys: 1-9 a technique (the table's order), hold R (or hover the reference's
// button) for the ground truth, S V E A F the views (shaded, visibility,
// signed error, absolute error, FLIP), 0 resets the view. Wheel: zoom about
// the cursor, to single pixels without smoothing; drag: pan. With counted
// work (ssm compare --count-work), W switches the metrics table and the
// per-pass chart between milliseconds and work (the chart then shows texel
// reads or invocations per pass, as chosen).
//
// The view is kept in the address's fragment (#technique=pcss&mode=signed&
// light=0&zoom=4&x=120&y=80&units=work&chart=reads), so a link opens the
// page on the same view.
//
// For tests, <body> carries data-viewer-ready, data-technique, data-mode,
// data-light, data-zoom and data-units; #readout carries data-pixel="x,y".
(function () {
  'use strict';
  const data = window.SSM_DATA;
  if (!data) {
    return;
  }
  const width = data.width;
  const height = data.height;
  const pixels = width * height;
  const body = document.body;
  const canvas = document.getElementById('viewer-canvas');
  const context = canvas.getContext('2d');
  const readout = document.getElementById('readout');
  const scaleNote = document.getElementById('viewer-scale');
  const techniques = data.techniques; // the ground truth first
  const reference = data.reference;
  const choices = techniques.filter((t) => t !== reference);

  function decode(base64, bytesPerValue) {
    const text = atob(base64);
    const bytes = new Uint8Array(text.length);
    for (let i = 0; i < text.length; i += 1) {
      bytes[i] = text.charCodeAt(i);
    }
    if (bytesPerValue === 1) {
      return bytes;
    }
    const view = new DataView(bytes.buffer);
    const values = new Float32Array(bytes.length / 2);
    for (let i = 0; i < values.length; i += 1) {
      values[i] = view.getUint16(2 * i, true) / 65535;
    }
    return values;
  }

  const covered = decode(data.covered, 1);
  const visibility = {};
  for (const name of techniques) {
    visibility[name] = data.images[name].visibility.map((b) => decode(b, 2));
  }
  const loaded = {};
  function image(path) {
    if (!path) {
      return null;
    }
    if (!loaded[path]) {
      const element = new Image();
      element.onload = draw;
      element.src = path;
      loaded[path] = element;
    }
    return loaded[path];
  }

  const state = {
    technique: choices.length > 0 ? choices[0] : reference,
    flipped: false,
    hoverReference: false,
    mode: 'shaded',
    light: 0,
    exposure: 0,
    zoom: 1,
    originX: 0,
    originY: 0,
    pointer: null,
    units: 'ms',
    chart: 'reads',
  };

  function shown() {
    return state.flipped || state.hoverReference ? reference : state.technique;
  }

  // The diverging map of the static heat maps: red where darker than the
  // ground truth (over-shadowing), blue where lighter, white where equal.
  const ERROR_SCALE = 0.5;
  function signedColour(error) {
    const t = Math.max(-1, Math.min(1, error / ERROR_SCALE));
    const fade = Math.round((1 - Math.abs(t)) * 255);
    return t < 0 ? [255, fade, fade] : [fade, fade, 255];
  }
  // A sequential map (black, red, yellow, white) for the absolute error.
  function absoluteColour(error) {
    const t = Math.max(0, Math.min(1, Math.abs(error) / ERROR_SCALE));
    return [Math.round(255 * Math.min(1, 3 * t)), Math.round(255 * Math.max(0, Math.min(1, 3 * t - 1))), Math.round(255 * Math.max(0, 3 * t - 2))];
  }

  const generated = {};
  function computed(name, mode, light) {
    const key = name + '|' + mode + '|' + light;
    if (generated[key]) {
      return generated[key];
    }
    const surface = document.createElement('canvas');
    surface.width = width;
    surface.height = height;
    const target = surface.getContext('2d');
    const picture = target.createImageData(width, height);
    const values = visibility[name][light];
    const truth = visibility[reference][light];
    for (let i = 0; i < pixels; i += 1) {
      let colour;
      if (!covered[i]) {
        colour = [96, 96, 96];
      } else if (mode === 'visibility') {
        const v = Math.round(values[i] * 255);
        colour = [v, v, v];
      } else if (mode === 'signed') {
        colour = signedColour(values[i] - truth[i]);
      } else {
        colour = absoluteColour(values[i] - truth[i]);
      }
      picture.data.set([colour[0], colour[1], colour[2], 255], 4 * i);
    }
    target.putImageData(picture, 0, 0);
    generated[key] = surface;
    return surface;
  }

  function source() {
    const name = shown();
    const files = data.images[name];
    if (state.mode === 'shaded') {
      return image(files.shaded);
    }
    if (state.mode === 'flip') {
      return image(files.flip);
    }
    return computed(name, state.mode, state.light);
  }

  function draw() {
    context.setTransform(1, 0, 0, 1, 0, 0);
    context.fillStyle = '#404040';
    context.fillRect(0, 0, canvas.width, canvas.height);
    context.imageSmoothingEnabled = false;
    context.filter = state.mode === 'shaded' && state.exposure !== 0 ? 'brightness(' + Math.pow(2, state.exposure) + ')' : 'none';
    const picture = source();
    const ready = picture && (!(picture instanceof HTMLImageElement) || (picture.complete && picture.naturalWidth > 0));
    context.setTransform(state.zoom, 0, 0, state.zoom, -state.originX * state.zoom, -state.originY * state.zoom);
    if (ready) {
      context.drawImage(picture, 0, 0, width, height);
    }
    context.filter = 'none';
    context.setTransform(1, 0, 0, 1, 0, 0);
    if (!ready) {
      context.fillStyle = '#ddd';
      context.fillText(state.mode === 'flip' && shown() === reference ? 'the ground truth has no FLIP map' : 'loading', 10, 20);
    }
    writeFragment();
    body.dataset.technique = shown();
    body.dataset.mode = state.mode;
    body.dataset.light = String(state.light);
    body.dataset.zoom = String(state.zoom);
    for (const button of document.querySelectorAll('#viewer-techniques button')) {
      button.classList.toggle('selected', button.dataset.technique === shown());
    }
    for (const button of document.querySelectorAll('#viewer-modes button')) {
      button.classList.toggle('selected', button.dataset.mode === state.mode);
    }
    for (const row of document.querySelectorAll('#metrics tbody tr')) {
      row.classList.toggle('selected', row.dataset.technique === state.technique);
    }
    scaleNote.textContent =
      state.mode === 'signed'
        ? 'signed error: red = darker than the ground truth (over-shadowing), blue = lighter; full colour at ±' + ERROR_SCALE
        : state.mode === 'absolute'
          ? 'absolute error: black 0, red, yellow, white at ' + ERROR_SCALE
          : state.mode === 'flip'
            ? 'FLIP (shaded against the shaded ground truth): magma, black 0 to yellow 1'
            : '';
    updateReadout();
  }

  function updateReadout() {
    if (!state.pointer) {
      return;
    }
    const x = Math.floor(state.originX + state.pointer[0] / state.zoom);
    const y = Math.floor(state.originY + state.pointer[1] / state.zoom);
    if (x < 0 || y < 0 || x >= width || y >= height) {
      readout.dataset.pixel = '';
      readout.textContent = 'outside the image';
      return;
    }
    const index = y * width + x;
    readout.dataset.pixel = x + ',' + y;
    if (!covered[index]) {
      readout.textContent = 'pixel (' + x + ', ' + y + '): background';
      return;
    }
    const truth = visibility[reference][state.light][index];
    const parts = techniques.map((name) => {
      const value = visibility[name][state.light][index];
      const difference = name === reference ? '' : ' (' + (value - truth >= 0 ? '+' : '') + (value - truth).toFixed(4) + ')';
      return '<span data-technique="' + name + '"' + (name === shown() ? ' class="selected"' : '') + '>' + name + ' ' + value.toFixed(4) + difference + '</span>';
    });
    readout.innerHTML = 'pixel (' + x + ', ' + y + '), light ' + state.light + ': ' + parts.join(' · ');
  }

  function clampOrigin() {
    const visibleWidth = canvas.width / state.zoom;
    const visibleHeight = canvas.height / state.zoom;
    state.originX = Math.max(Math.min(state.originX, width - visibleWidth / 2), -visibleWidth / 2);
    state.originY = Math.max(Math.min(state.originY, height - visibleHeight / 2), -visibleHeight / 2);
  }

  function select(name) {
    state.technique = name;
    draw();
  }

  // Technique and view buttons.
  const techniqueBar = document.getElementById('viewer-techniques');
  techniques.forEach((name) => {
    const button = document.createElement('button');
    button.dataset.technique = name;
    const key = choices.indexOf(name);
    button.textContent = name === reference ? 'R ' + name + ' (hold)' : (key < 9 ? key + 1 + ' ' : '') + name;
    if (name === reference) {
      button.addEventListener('mouseenter', () => {
        state.hoverReference = true;
        draw();
      });
      button.addEventListener('mouseleave', () => {
        state.hoverReference = false;
        draw();
      });
    } else {
      button.addEventListener('click', () => select(name));
    }
    techniqueBar.appendChild(button);
  });
  const modes = [
    ['shaded', 'S shaded'],
    ['visibility', 'V visibility'],
    ['signed', 'E signed error'],
    ['absolute', 'A absolute error'],
    ['flip', 'F FLIP'],
  ];
  const modeBar = document.getElementById('viewer-modes');
  for (const [mode, label] of modes) {
    const button = document.createElement('button');
    button.dataset.mode = mode;
    button.textContent = label;
    button.addEventListener('click', () => {
      state.mode = mode;
      draw();
    });
    modeBar.appendChild(button);
  }
  const lightChoice = document.getElementById('viewer-light');
  for (let light = 0; light < data.lights; light += 1) {
    const option = document.createElement('option');
    option.value = String(light);
    option.textContent = 'light ' + light;
    lightChoice.appendChild(option);
  }
  lightChoice.addEventListener('change', () => {
    state.light = Number(lightChoice.value);
    draw();
  });
  const exposure = document.getElementById('viewer-exposure');
  exposure.addEventListener('input', () => {
    state.exposure = Number(exposure.value);
    document.getElementById('viewer-exposure-value').textContent = (state.exposure >= 0 ? '+' : '') + state.exposure.toFixed(1) + ' EV';
    draw();
  });

  document.addEventListener('keydown', (event) => {
    if (event.target instanceof HTMLInputElement || event.target instanceof HTMLSelectElement) {
      return;
    }
    const key = event.key.toLowerCase();
    if (key === 'w' && data.work_columns) {
      setUnits(state.units === 'ms' ? 'work' : 'ms');
    } else if (key >= '1' && key <= '9' && Number(key) <= choices.length) {
      select(choices[Number(key) - 1]);
    } else if (key === 'r') {
      state.flipped = true;
      draw();
    } else if (key === '0') {
      state.zoom = 1;
      state.originX = 0;
      state.originY = 0;
      draw();
    } else {
      const mode = { s: 'shaded', v: 'visibility', e: 'signed', a: 'absolute', f: 'flip' }[key];
      if (mode) {
        state.mode = mode;
        draw();
      }
    }
  });
  document.addEventListener('keyup', (event) => {
    if (event.key.toLowerCase() === 'r') {
      state.flipped = false;
      draw();
    }
  });

  // The pointer in canvas pixels, from inside its border (fractional, unlike offsetX).
  function pointerOf(event) {
    const rect = canvas.getBoundingClientRect();
    return [event.clientX - rect.left - canvas.clientLeft, event.clientY - rect.top - canvas.clientTop];
  }
  canvas.addEventListener(
    'wheel',
    (event) => {
      event.preventDefault();
      const [mx, my] = pointerOf(event);
      // The pixel under the cursor stays under it.
      const pointX = state.originX + mx / state.zoom;
      const pointY = state.originY + my / state.zoom;
      const factor = Math.pow(1.25, -Math.sign(event.deltaY) * Math.min(4, Math.max(1, Math.abs(event.deltaY) / 100)));
      state.zoom = Math.max(0.25, Math.min(64, state.zoom * factor));
      state.originX = pointX - mx / state.zoom;
      state.originY = pointY - my / state.zoom;
      clampOrigin();
      state.pointer = [mx, my];
      draw();
    },
    { passive: false },
  );
  let dragging = null;
  canvas.addEventListener('mousedown', (event) => {
    dragging = [event.clientX, event.clientY];
  });
  window.addEventListener('mouseup', () => {
    dragging = null;
  });
  canvas.addEventListener('mousemove', (event) => {
    state.pointer = pointerOf(event);
    if (dragging) {
      state.originX -= (event.clientX - dragging[0]) / state.zoom;
      state.originY -= (event.clientY - dragging[1]) / state.zoom;
      dragging = [event.clientX, event.clientY];
      clampOrigin();
      draw();
    } else {
      updateReadout();
    }
  });

  // The metrics table: sortable by any column, a click on a row selects its technique. Its
  // columns are the milliseconds' or, switched to work, the counted work's.
  const table = document.getElementById('metrics');
  let columns = data.columns;
  const head = table.createTHead().insertRow();
  function fillHead() {
    head.textContent = '';
    columns.forEach(([key, label]) => {
      const cell = document.createElement('th');
      cell.textContent = label;
      cell.dataset.key = key;
      cell.title = 'sort by ' + label;
      cell.addEventListener('click', () => sortBy(key));
      head.appendChild(cell);
    });
  }
  fillHead();
  // Counts are whole numbers; a count not made is null, shown as '-' (never 0).
  const COUNTS = ['vertex_invocations', 'fragment_invocations', 'compute_invocations', 'texel_reads', 'atomics', 'target_bytes', 'storage_bytes'];
  function cellText(key, value) {
    if (COUNTS.includes(key)) {
      return typeof value === 'number' ? String(value) : '-';
    }
    return typeof value === 'number' ? (Number.isFinite(value) ? value.toFixed(key === 'gpu_ms' ? 2 : 4) : '') : value === null || value === undefined ? '' : String(value);
  }
  const tableBody = table.createTBody();
  let sorted = { key: null, ascending: true };
  function fill(rows) {
    tableBody.textContent = '';
    for (const row of rows) {
      const line = tableBody.insertRow();
      line.dataset.technique = row.technique;
      for (const [key] of columns) {
        const cell = line.insertCell();
        cell.textContent = cellText(key, row[key]);
      }
      line.addEventListener('click', () => {
        if (row.light !== null && row.light !== undefined && row.light !== '') {
          state.light = Number(row.light);
          lightChoice.value = String(state.light);
        }
        if (row.technique !== reference) {
          select(row.technique);
        }
      });
    }
  }
  function sortBy(key) {
    sorted = { key, ascending: sorted.key === key ? !sorted.ascending : true };
    const rows = data.rows.slice().sort((a, b) => {
      const x = a[key];
      const y = b[key];
      // Uncounted (null) after every count.
      const order =
        typeof x === 'number' && typeof y === 'number'
          ? x - y
          : typeof x === 'number' && COUNTS.includes(key)
            ? -1
            : typeof y === 'number' && COUNTS.includes(key)
              ? 1
              : String(x).localeCompare(String(y));
      return sorted.ascending ? order : -order;
    });
    for (const cell of head.cells) {
      cell.dataset.sorted = cell.dataset.key === key ? (sorted.ascending ? 'ascending' : 'descending') : '';
    }
    table.dataset.sortedBy = key + (sorted.ascending ? ' ascending' : ' descending');
    fill(rows);
    draw();
  }
  // Milliseconds or work: the table's columns and the per-pass chart's source (the chart's
  // data-ms, data-reads, data-invocations attributes name the files drawn).
  const unitBar = document.getElementById('viewer-units');
  const passChart = document.getElementById('pass-chart');
  const charts = passChart ? ['reads', 'invocations'].filter((name) => passChart.dataset[name]) : [];
  function setUnits(units, chart) {
    state.units = data.work_columns ? units : 'ms';
    if (chart && charts.includes(chart)) {
      state.chart = chart;
    }
    if (!charts.includes(state.chart) && charts.length > 0) {
      state.chart = charts[0];
    }
    columns = state.units === 'work' ? data.work_columns : data.columns;
    fillHead();
    sorted = { key: null, ascending: true };
    table.dataset.sortedBy = '';
    fill(data.rows);
    if (passChart) {
      const file = state.units === 'work' ? passChart.dataset[state.chart] : passChart.dataset.ms;
      if (file) {
        passChart.src = file;
      }
    }
    body.dataset.units = state.units;
    for (const button of unitBar.querySelectorAll('button')) {
      button.classList.toggle('selected', button.dataset.units === state.units || (state.units === 'work' && button.dataset.chart === state.chart));
    }
    draw();
  }
  if (data.work_columns) {
    const unitChoices = [['ms', null, 'milliseconds'], ['work', null, 'W work']].concat(
      charts.map((chart) => ['work', chart, 'chart: ' + (chart === 'reads' ? 'texel reads' : 'invocations')]),
    );
    for (const [units, chart, label] of unitChoices) {
      const button = document.createElement('button');
      if (chart) {
        button.dataset.chart = chart;
      } else {
        button.dataset.units = units;
      }
      button.textContent = label;
      button.addEventListener('click', () => setUnits(units, chart));
      unitBar.appendChild(button);
    }
  }
  body.dataset.units = state.units;

  // The view in the address's fragment: read once at load, rewritten on every change.
  const MODES = ['shaded', 'visibility', 'signed', 'absolute', 'flip'];
  function readFragment() {
    const fields = new URLSearchParams(window.location.hash.slice(1));
    const technique = fields.get('technique');
    if (technique && choices.includes(technique)) {
      state.technique = technique;
    }
    if (MODES.includes(fields.get('mode'))) {
      state.mode = fields.get('mode');
    }
    const number = (key, low, high) => {
      const value = Number(fields.get(key));
      return fields.has(key) && Number.isFinite(value) ? Math.max(low, Math.min(high, value)) : null;
    };
    const light = number('light', 0, data.lights - 1);
    if (light !== null) {
      state.light = Math.floor(light);
      lightChoice.value = String(state.light);
    }
    const zoom = number('zoom', 0.25, 64);
    if (zoom !== null) {
      state.zoom = zoom;
    }
    const x = number('x', -width, 2 * width);
    const y = number('y', -height, 2 * height);
    if (x !== null && y !== null) {
      state.originX = x;
      state.originY = y;
    }
    if (fields.get('units') === 'work' && data.work_columns) {
      state.units = 'work';
    }
    if (charts.includes(fields.get('chart'))) {
      state.chart = fields.get('chart');
    }
  }
  function writeFragment() {
    const fields = new URLSearchParams({
      technique: state.technique,
      mode: state.mode,
      light: String(state.light),
      zoom: String(Math.round(state.zoom * 1000) / 1000),
      x: String(Math.round(state.originX * 100) / 100),
      y: String(Math.round(state.originY * 100) / 100),
    });
    if (state.units === 'work') {
      fields.set('units', 'work');
      fields.set('chart', state.chart);
    }
    history.replaceState(null, '', '#' + fields.toString());
  }
  readFragment();
  setUnits(state.units, state.chart);
  body.dataset.viewerReady = '1';
})();
