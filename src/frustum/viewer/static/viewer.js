// frustum viewer page: the picture, the controls and the pipeline panel. Shared by the Jupyter widget and
// `frustum serve`; `transport.send(message)` sends JSON to Python, `transport.listen(handler)` delivers
// (header, bytes) pairs back (bytes: the RGBA of a frame, top row first, or null).

function mountViewer(el, transport) {
  const latencies = [];
  const api = { latencies, frames: 0, state: null, pick: null, lastSeq: null, log: [] };
  el.classList.add("frustum-viewer");
  el.innerHTML = `
    <div class="fv-error" hidden></div>
    <div class="fv-main">
      <div class="fv-left">
        <canvas class="fv-canvas" tabindex="0"></canvas>
        <div class="fv-controls">
          <label>projection <select data-control="projection"></select></label>
          <label>shading <select data-control="shading"></select></label>
          <label>mode <select data-control="mode"></select></label>
          <label><input type="checkbox" data-control="depth_cue"> depth cue</label>
          <label><input type="checkbox" data-control="shadows"> shadows</label>
          <button class="fv-reset">reset</button>
        </div>
        <div class="fv-help">drag: orbit · right/shift drag: pan · wheel: zoom · click: pick ·
          keys f t r i: front, top, right, isometric · 0: reset</div>
      </div>
      <div class="fv-panel">
        <label><input type="checkbox" class="fv-rowform"> row-vector form (P' = P·Mᵀ)</label>
        <div class="fv-matrices"></div>
        <div class="fv-trace"><em>click the picture to trace a surface point</em></div>
      </div>
    </div>
    <details class="fv-steps">
      <summary>steps: watch a visible-surface method work on this view</summary>
      <div class="fv-steps-bar">
        <label>method <select class="fv-steps-method"></select></label>
        <button class="fv-steps-record">record this view</button>
        <span class="fv-steps-status"></span>
      </div>
      <div class="fv-steps-nav" hidden>
        <button class="fv-steps-prev" title="previous step">&#9664;</button>
        <input type="range" class="fv-steps-slider" min="0" max="0" value="0" step="1" aria-label="step">
        <button class="fv-steps-next" title="next step">&#9654;</button>
        <span class="fv-steps-counter"></span>
      </div>
      <div class="fv-steps-figure"></div>
    </details>`;
  const q = (s) => el.querySelector(s);
  const canvas = q(".fv-canvas");
  const context = canvas.getContext("2d");
  const scratch = document.createElement("canvas");
  const scratchContext = scratch.getContext("2d");
  const errorBox = q(".fv-error");
  const rowForm = q(".fv-rowform");
  let seq = 0;
  const sentAt = new Map();
  let inFlight = false;
  let pendingMove = null;
  let drag = null;
  let restTimer = null;

  function note(text) { api.log.push(text); if (api.log.length > 100) api.log.shift(); }  // for debugging
  function send(message) { note("> " + message.type + (message.action ? " " + message.action : "")); transport.send(message); }

  // One interactive request in flight at a time: moves and wheel turns that come meanwhile are merged (the
  // latest position, the summed wheel delta) and sent when the frame arrives, so Python never falls behind.
  let pendingWheel = null;
  function sendMove(message) {
    if (inFlight) { pendingMove = message; return; }
    inFlight = true;
    send(message);
  }
  function sendWheel(message) {
    if (inFlight) {
      if (pendingWheel) message.delta = Math.max(-5000, Math.min(5000, pendingWheel.delta + message.delta));
      pendingWheel = message;
      return;
    }
    inFlight = true;
    send(message);
  }
  function flushPending() {
    const messages = [pendingWheel, pendingMove].filter((m) => m);
    pendingWheel = pendingMove = null;
    if (messages.length) { inFlight = true; messages.forEach(send); }
    else if (restWanted) { restWanted = false; send({ type: "rest" }); }
  }
  // the full frame is asked for once the interactive ones are all answered, so it is the last one drawn
  let restWanted = false;
  function requestRest() {
    if (inFlight || pendingWheel || pendingMove) restWanted = true; else send({ type: "rest" });
  }

  function imagePoint(event) {
    // image pixels (x right, y down) from the canvas's content box (inside its border)
    const box = canvas.getBoundingClientRect();
    const sx = canvas.width / canvas.clientWidth, sy = canvas.height / canvas.clientHeight;
    return [(event.clientX - box.left - canvas.clientLeft) * sx, (event.clientY - box.top - canvas.clientTop) * sy];
  }

  canvas.addEventListener("contextmenu", (event) => event.preventDefault());
  canvas.addEventListener("pointerdown", (event) => {
    canvas.focus();
    const [x, y] = imagePoint(event);
    drag = { x0: x, y0: y, moved: false };
    canvas.setPointerCapture(event.pointerId);
    send({ type: "pointer", action: "down", x, y, button: event.button, shift: event.shiftKey });
    event.preventDefault();
  });
  canvas.addEventListener("pointermove", (event) => {
    if (!drag) return;
    const [x, y] = imagePoint(event);
    if (Math.abs(x - drag.x0) + Math.abs(y - drag.y0) > 2) drag.moved = true;
    if (!drag.moved) return;
    seq += 1;
    sentAt.set(seq, event.timeStamp);
    sendMove({ type: "pointer", action: "move", x, y, seq });
  });
  function endDrag(event) {
    if (!drag) return;
    const [x, y] = imagePoint(event);
    const clicked = !drag.moved;
    drag = null;
    pendingMove = null;
    send({ type: "pointer", action: "up" });
    if (clicked) send({ type: "pick", x, y });
  }
  canvas.addEventListener("pointerup", endDrag);
  canvas.addEventListener("pointercancel", endDrag);
  canvas.addEventListener("wheel", (event) => {
    event.preventDefault();
    const delta = event.deltaMode === 1 ? event.deltaY * 33 : event.deltaMode === 2 ? event.deltaY * 400 : event.deltaY;
    seq += 1;
    sentAt.set(seq, event.timeStamp);
    sendWheel({ type: "wheel", delta: Math.max(-5000, Math.min(5000, delta)), seq });
    clearTimeout(restTimer);
    restTimer = setTimeout(requestRest, 250);
  }, { passive: false });
  canvas.addEventListener("keydown", (event) => {
    send({ type: "key", key: event.key });
  });
  q(".fv-reset").addEventListener("click", () => send({ type: "reset" }));
  for (const input of el.querySelectorAll("[data-control]")) {
    input.addEventListener("change", () => {
      const value = input.type === "checkbox" ? input.checked : input.value;
      send({ type: "control", name: input.dataset.control, value });
    });
  }
  rowForm.addEventListener("change", () => { showMatrices(); showTrace(); });

  // The steps panel: Python records the chosen method on the current view (a small copy of it) and sends every
  // step's SVG figure at once; the slider and the buttons then step through them here, with no further message.
  const stepsMethod = q(".fv-steps-method"), stepsStatus = q(".fv-steps-status"), stepsNav = q(".fv-steps-nav");
  const stepsSlider = q(".fv-steps-slider"), stepsFigure = q(".fv-steps-figure");
  api.steps = null;
  api.stepIndex = null;
  function stepsStale() {
    return !!(api.steps && api.state && JSON.stringify(api.steps.camera) !== JSON.stringify(api.state.camera));
  }
  function showStepsStatus() {
    const record = api.steps;
    if (!record) return;
    if (record.error) { stepsStatus.textContent = record.algorithm + ": " + record.error; return; }
    stepsStatus.textContent = `${record.algorithm}: ${record.figures.length} steps at ${record.size.join("×")} pixels` +
      (stepsStale() ? " (recorded on an earlier view: record again to follow the camera)" : "");
    stepsStatus.dataset.stale = String(stepsStale());
  }
  function showStep(i) {
    const record = api.steps;
    if (!record || !record.figures) return;
    i = Math.max(0, Math.min(record.figures.length - 1, i));
    api.stepIndex = i;
    stepsSlider.value = String(i);
    q(".fv-steps-counter").textContent = `${i + 1} / ${record.figures.length}: ${record.titles[i]}`;
    stepsFigure.innerHTML = record.figures[i];
    stepsFigure.dataset.step = String(i);
  }
  function showSteps(record) {
    api.steps = record;
    stepsNav.hidden = !record.figures;
    stepsFigure.innerHTML = "";
    delete stepsFigure.dataset.step;
    q(".fv-steps-record").disabled = false;
    if (record.figures) {
      stepsSlider.max = String(record.figures.length - 1);
      showStep(0);
    }
    showStepsStatus();
  }
  q(".fv-steps-record").addEventListener("click", () => {
    if (!stepsMethod.value) return;
    q(".fv-steps-record").disabled = true;
    stepsStatus.textContent = "recording " + stepsMethod.value + " ...";
    send({ type: "steps", algorithm: stepsMethod.value });
  });
  stepsSlider.addEventListener("input", () => showStep(parseInt(stepsSlider.value, 10)));
  q(".fv-steps-prev").addEventListener("click", () => showStep(api.stepIndex - 1));
  q(".fv-steps-next").addEventListener("click", () => showStep(api.stepIndex + 1));

  function formatNumber(v) {
    if (v === null || v === undefined) return "";
    const r = Math.round(v);
    const shown = Math.abs(v - r) < 1e-12 ? r : v;
    return Number(shown.toPrecision(5)).toString();
  }

  function matrixTable(name, matrix) {
    const form = rowForm.checked ? matrix[0].map((_, j) => matrix.map((row) => row[j])) : matrix;
    const rows = form.map((row, i) => "<tr>" + row.map((v, j) =>
      `<td data-row="${i}" data-col="${j}" data-value="${v}">${formatNumber(v)}</td>`).join("") + "</tr>").join("");
    return `<table class="fv-matrix" data-matrix="${name}" data-form="${rowForm.checked ? "row" : "column"}">${rows}</table>`;
  }

  function showMatrices() {
    const state = api.state;
    if (!state) return;
    const names = { view: "view_from_world (viewing)", projection: "clip_from_view (projection)",
      viewport: "window_from_ndc (viewport)" };
    q(".fv-matrices").innerHTML = Object.keys(names).map((key) =>
      `<div class="fv-block"><div class="fv-title">${names[key]}</div>${matrixTable(key, state.matrices[key])}</div>`).join("");
  }

  function showTrace() {
    const pick = api.pick;
    if (!pick) return;
    const box = q(".fv-trace");
    if (!pick.hit) { box.innerHTML = `<div class="fv-title">pixel ${pick.pixel.join(", ")}: ${pick.label}</div>`; return; }
    const point = (p) => "(" + p.map(formatNumber).join(", ") + ")";
    box.innerHTML = `<div class="fv-title">pixel ${pick.pixel.join(", ")} — ${pick.label}</div>` +
      pick.stages.map((stage, k) => {
        let extra = "";
        if (stage.code !== undefined) {
          extra = ` region code ${stage.code.toString(2).padStart(6, "0")}` +
            (stage.regions.length ? " (outside " + stage.regions.join(", ") + ")" : " (inside)");
        }
        const matrix = stage.matrix ? matrixTable("stage-" + stage.name, stage.matrix) : "";
        return `<div class="fv-stage" data-stage="${stage.name}"><div class="fv-title">${k + 1}. ${stage.title}</div>` +
          `${matrix}<div class="fv-point" data-point="${stage.point.join(",")}">${point(stage.point)}${extra}</div></div>`;
      }).join("");
  }

  function showState(state) {
    api.state = state;
    for (const input of el.querySelectorAll("[data-control]")) {
      const name = input.dataset.control;
      if (input.tagName === "SELECT" && input.options.length === 0) {
        for (const value of state.choices[name]) input.add(new Option(value, value));
      }
      if (input.type === "checkbox") input.checked = !!state.controls[name]; else input.value = state.controls[name];
    }
    if (state.steps && stepsMethod.options.length === 0) {
      for (const value of state.steps.methods) stepsMethod.add(new Option(value, value));
    }
    errorBox.hidden = !state.error;
    errorBox.textContent = state.error || "";
    showMatrices();
    showStepsStatus();
  }

  function drawFrame(header, bytes) {
    const camera = header.state && header.state.camera;
    if (camera && (canvas.width !== camera.width || canvas.height !== camera.height)) {
      canvas.width = camera.width;
      canvas.height = camera.height;
      q(".fv-left").style.width = `${camera.width + 2}px`;  // the controls wrap under the picture
    }
    scratch.width = header.width;
    scratch.height = header.height;
    scratchContext.putImageData(new ImageData(new Uint8ClampedArray(bytes), header.width, header.height), 0, 0);
    context.imageSmoothingEnabled = header.width !== canvas.width;
    context.drawImage(scratch, 0, 0, canvas.width, canvas.height);
    api.frames += 1;
    api.quality = header.quality;
    api.drawn = { quality: header.quality, camera: api.state && api.state.camera, zoom: api.state && api.state.zoom };
    if (header.seq !== null && header.seq !== undefined && sentAt.has(header.seq)) {
      const start = sentAt.get(header.seq);
      latencies.push(performance.now() - start);
      for (const key of sentAt.keys()) if (key <= header.seq) sentAt.delete(key);
      api.lastSeq = header.seq;
    }
    canvas.dataset.frames = String(api.frames);
  }

  transport.listen((header, bytes) => {
    note("< " + header.type + (header.quality ? " " + header.quality : ""));
    if (header.type === "frame") {
      if (header.state) api.state = header.state;
      drawFrame(header, bytes);
      if (header.state) showState(header.state);  // after the picture: the panel never delays a frame
      inFlight = false;
      flushPending();
    } else if (header.type === "state") {
      showState(header);
    } else if (header.type === "pick") {
      api.pick = header;
      showTrace();
    } else if (header.type === "steps") {
      showSteps(header);
    } else if (header.type === "error") {
      q(".fv-steps-record").disabled = false;
      errorBox.hidden = !header.message;
      errorBox.textContent = header.message || "";
      inFlight = false;
      flushPending();
    } else if (header.type === "ignored") {
      q(".fv-steps-record").disabled = false;
      inFlight = false;
      flushPending();
    }
  });
  return api;
}
