// The web viewer (web/index.html?pack=URL): streams a .gip by HTTP Range requests — the 20-byte header, the
// manifest, then the chunks coarse → fine in ranges that double in size — into the WASM decoder
// (geomip.js; decoding on a worker, decode-worker.js), and redraws with the WebGL2 renderer (renderer.js)
// each time more complete chunks have arrived: the model refines in place. Errors (a bad URL, an HTTP
// error, a file that is not a pack, a stream cut short, a corrupt chunk) are one line on the page; the last
// good level stays on screen.
//
// URL parameters: pack=URL (required); morph=T (0..1, fixed morph time between model `from` and model `to`;
// default: a slider, at 0), from=I, to=J (models, default 0 and 1); schedule=linear|wavelet (wavelet: 4
// bands); stop=N or stop=P% (stop fetching after N bytes / P % of the file: a prefix, on purpose);
// first=N (bytes of the first chunk range, default 16384); timeout=S (seconds without a byte before a stalled
// server ends the stream, default 20); hud=0 hides the text (for screenshots). A parameter that is not a
// number in its range is an error line, nothing is fetched.
// For tests and scripts, window.geomipViewer holds the state: { phase: 'loading'|'done'|'error', bytes,
// fileSize, level, levels (each refinement: bytes, level), models, message, draws, decodes, decodeMs (time
// spent decoding), requests, camera }.
import { createDecoder, GeomipError } from './geomip.js';
import { Renderer, framingDistance } from './renderer.js';

const params = new URLSearchParams(location.search);
const canvas = document.getElementById('view');
const statusLine = document.getElementById('status');
const errorLine = document.getElementById('error');
const slider = document.getElementById('morph');

const state = window.geomipViewer = {
  phase: 'loading', bytes: 0, fileSize: 0, level: -1, levels: [], models: 0, message: '', draws: 0, decodes: 0,
  decodeMs: 0, requests: [],
};
if (params.get('hud') === '0') document.getElementById('hud').hidden = true;
const camera = state.camera = { yaw: 0.6, pitch: 0.35, distance: 3.2, fovYDeg: 35 };
// Until the user turns or zooms, each refinement frames the models (~70 % of the height, as geomip-view).
let cameraMoved = false;
const view = {
  source: Number(params.get('from') ?? 0), target: Number(params.get('to') ?? 1),
  t: Number(params.get('morph') ?? 0), schedule: params.get('schedule') === 'wavelet' ? 'wavelet' : 'linear',
};
const bands = view.schedule === 'wavelet' ? 4 : 1;
slider.value = String(view.t);

let renderer = null;
const gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
if (!gl) fail('this browser has no WebGL2');
else renderer = new Renderer(gl);

function fail(message) {
  if (state.bytes === 0) statusLine.textContent = '';  // not "loading…" beside the error
  state.phase = 'error';
  state.message = message;
  errorLine.textContent = message;
  redraw();
}

function showStatus(name) {
  const pct = state.fileSize ? ` (${(100 * state.bytes / state.fileSize).toFixed(1)} %)` : '';
  const total = state.fileSize ? ` of ${state.fileSize.toLocaleString('en')}` : '';
  const level = state.level >= 0 ? `, level ${state.level}` : '';
  statusLine.textContent = `${name}${state.bytes.toLocaleString('en')}${total} bytes${pct}${level}`;
}

let frameQueued = false;
function redraw() {
  if (!renderer || frameQueued) return;
  frameQueued = true;
  requestAnimationFrame(() => {
    frameQueued = false;
    const dpr = window.devicePixelRatio || 1;
    const width = Math.round(canvas.clientWidth * dpr), height = Math.round(canvas.clientHeight * dpr);
    if (canvas.width !== width || canvas.height !== height) { canvas.width = width; canvas.height = height; }
    renderer.draw({ ...view, camera, width, height });
    ++state.draws;
  });
}

// ---- orbit and zoom: mouse (drag, wheel) and touch (one finger drags, two pinch) --------------------------
const pointers = new Map();
canvas.addEventListener('pointerdown', (e) => { canvas.setPointerCapture(e.pointerId); pointers.set(e.pointerId, e); });
canvas.addEventListener('pointerup', (e) => pointers.delete(e.pointerId));
canvas.addEventListener('pointercancel', (e) => pointers.delete(e.pointerId));
canvas.addEventListener('pointermove', (e) => {
  const last = pointers.get(e.pointerId);
  if (!last) return;
  cameraMoved = true;
  if (pointers.size === 1) {
    camera.yaw -= (e.clientX - last.clientX) * 0.01;
    camera.pitch = Math.min(1.5, Math.max(-1.5, camera.pitch + (e.clientY - last.clientY) * 0.01));
  } else if (pointers.size === 2) {
    const other = [...pointers.values()].find((p) => p.pointerId !== e.pointerId);
    const before = Math.hypot(last.clientX - other.clientX, last.clientY - other.clientY);
    const after = Math.hypot(e.clientX - other.clientX, e.clientY - other.clientY);
    if (before > 0 && after > 0) camera.distance = Math.min(20, Math.max(0.5, camera.distance * before / after));
  }
  pointers.set(e.pointerId, e);
  redraw();
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  cameraMoved = true;
  camera.distance = Math.min(20, Math.max(0.5, camera.distance * Math.exp(e.deltaY * 0.001)));
  redraw();
}, { passive: false });
window.addEventListener('resize', redraw);
slider.addEventListener('input', () => { view.t = Number(slider.value); redraw(); });

// ---- streaming -----------------------------------------------------------------------------------------
class StreamError extends Error {}
class UsageError extends Error {}  // a URL parameter the pack cannot honour: said alone

/// GET `url` bytes [begin, end) (end = null: to the end), pushing the body into the decoder as it arrives.
/// `onBytes(bytes)` after each piece. A server that ignores Range (200) sends the whole file: the bytes before `begin` are skipped and the
/// rest is read to the end (one request in all). Returns true when the body was the whole rest of the file.
async function fetchRange(url, decoder, begin, end, onBytes) {
  let response;
  try {
    response = await fetch(url, { headers: { Range: `bytes=${begin}-${end === null ? '' : end - 1}` } });
  } catch (e) {
    throw new StreamError(`cannot fetch ${url}: ${e.message} (a bad URL, the server down, or no CORS headers)`);
  }
  if (response.status === 416 && begin === 0)  // Range Not Satisfiable at byte 0: the file is empty
    throw new StreamError(`${url} is empty: not a geomip pack`);
  if (response.status !== 206 && response.status !== 200)
    throw new StreamError(`cannot fetch ${url}: HTTP ${response.status} ${response.statusText}`.trim());
  const whole = response.status === 200;
  state.requests.push({ begin, end, status: response.status });
  let skip = whole ? begin : 0;
  const reader = response.body.getReader();
  for (;;) {
    let chunk;
    try {
      chunk = await readWithin(reader, url, decoder);
    } catch (e) {
      if (e instanceof StreamError) throw e;
      throw new StreamError(`the stream of ${url} broke off at ${decoder.size.toLocaleString('en')} bytes (${e.message})`);
    }
    if (chunk.done) break;
    let bytes = chunk.value;
    if (skip > 0) { const n = Math.min(skip, bytes.length); bytes = bytes.subarray(n); skip -= n; }
    if (!whole && end !== null && decoder.size + bytes.length > end) bytes = bytes.subarray(0, end - decoder.size);
    // A server without Range sends everything at once, in pieces of any size: the bytes go in up to the
    // header, then up to the manifest's end, so that a file that is no pack is not read to its end and a
    // body longer than the pack (or stop=) is cut at its size.
    let notPack = false;
    while (bytes.length > 0) {
      let n = bytes.length;
      if (whole && packLimit === Infinity) {
        try {
          const need = decoder.size < 20 ? 20 : decoder.needed();
          const layout = decoder.size >= need ? decoder.layout() : null;
          if (layout)
            packLimit = limitFor(layout);
          else
            n = Math.min(n, Math.max(1, need - decoder.size));
        } catch (e) {
          if (!(e instanceof GeomipError)) throw e;
          notPack = true;  // the caller says what is wrong with it
          break;
        }
      }
      n = Math.min(n, Math.max(0, packLimit - decoder.size));
      if (n === 0) break;
      decoder.push(bytes.subarray(0, n));
      onBytes(bytes.subarray(0, n));
      bytes = bytes.subarray(n);
    }
    if (notPack || decoder.size >= packLimit || (stopAt !== null && decoder.size >= stopAt) || corrupt) {
      reader.cancel().catch(() => {});
      break;
    }
  }
  return whole;
}

let stopAt = null;

/// The URL parameters that are numbers, checked before anything is fetched: '' or one line for the page.
function checkParams() {
  const number = (name, ok, what) => {
    const v = params.get(name);
    if (v === null) return '';
    const x = Number(v.endsWith('%') && name === 'stop' ? v.slice(0, -1) : v);
    return v.trim() !== '' && Number.isFinite(x) && ok(x) ? '' : `${name}=${v}: ${what}`;
  };
  return number('morph', (x) => x >= 0 && x <= 1, 'a morph time in [0, 1]') ||
      number('from', (x) => Number.isInteger(x) && x >= 0, 'a model index (0, 1, ...)') ||
      number('to', (x) => Number.isInteger(x) && x >= 0, 'a model index (0, 1, ...)') ||
      number('stop', (x) => x > 0, 'a byte count or a percentage above 0') ||
      number('first', (x) => Number.isInteger(x) && x >= 1, 'a byte count of at least 1') ||
      number('timeout', (x) => x > 0, 'seconds above 0');
}

// A server that stops sending (the connection open, no bytes) ends the stream after this many seconds without
// a byte (timeout=S, default 20), as geomip-view's --timeout: the last good level stays.
const stallSeconds = Number(params.get('timeout') ?? 20);

/// reader.read(), or a StreamError when no byte arrives for stallSeconds.
function readWithin(reader, url, decoder) {
  let timer;
  const stalled = new Promise((_, reject) => {
    timer = setTimeout(() => {
      // Rejected before the cancel, which resolves the pending read (done) and would win the race.
      reject(new StreamError(
          `the server of ${url} sent nothing for ${stallSeconds} s after ` +
          `${decoder.size.toLocaleString('en')} bytes`));
      reader.cancel().catch(() => {});
    }, stallSeconds * 1000);
  });
  return Promise.race([reader.read(), stalled]).finally(() => clearTimeout(timer));
}

/// The most bytes worth reading: the pack's size once its manifest is known (a server that sends more, or
/// never ends its body, is cut there), less with stop=; Infinity before.
let packLimit = Infinity;
function limitFor(layout) {
  const stop = params.get('stop');
  if (stop) stopAt = stop.endsWith('%') ? Math.floor(layout.fileSize * parseFloat(stop) / 100) : Number(stop);
  return Math.min(layout.fileSize, stopAt ?? Infinity);
}

/// Scene decodes off the main thread (decode-worker.js) when module workers are available, else on it.
class SceneSource {
  constructor(decoder) {
    this.decoder = decoder;
    this.pending = [];
    try {
      this.worker = new Worker(new URL('./decode-worker.js', import.meta.url), { type: 'module' });
      this.worker.onmessage = ({ data }) => this.pending.shift()?.(data);
      this.worker.onerror = () => {  // the worker could not start: decode here from now on
        this.worker = null;
        for (const resolve of this.pending.splice(0)) resolve(this.decodeHere());
      };
    } catch (_) {
      this.worker = null;
    }
  }
  push(bytes) { if (this.worker) this.worker.postMessage({ type: 'push', bytes: bytes.slice() }); }
  decodeHere() {
    const t0 = performance.now();
    const scene = this.decoder.scene({ bands });
    return { type: 'scene', scene, size: this.decoder.size, ms: performance.now() - t0 };
  }
  scene() {
    if (!this.worker) return Promise.resolve(this.decodeHere());
    return new Promise((resolve) => {
      this.pending.push(resolve);
      this.worker.postMessage({ type: 'scene', bands });
    });
  }
}

let requestedChunks = -1;
let statusName = '';  // "<file>: ", the status line's prefix
let inFlight = null;
let again = false;
let corrupt = null;

/// Starts a decode when more complete chunks have arrived than at the last one; one decode at a time (chunks
/// that arrive meanwhile are decoded next). The result replaces the models on screen.
function refine(source, layout) {
  if (!layout) return;
  let complete = 0;
  while (complete < layout.chunks.length &&
         layout.chunks[complete].offset + layout.chunks[complete].size <= source.decoder.size) ++complete;
  if (complete === requestedChunks) return;
  if (inFlight) { again = true; return; }
  requestedChunks = complete;
  inFlight = source.scene().then((result) => {
    if (result.type === 'error') throw new Error(result.message);
    const { scene, size, ms } = result;
    state.decodeMs += ms;
    ++state.decodes;
    // Recorded before anything else: a corrupt first chunk leaves no model to show, and must still be said.
    if (scene.status === 'corrupt' && !corrupt)
      corrupt = new StreamError(
          `a chunk of the pack is corrupt (CRC) after ${scene.bytesUsed.toLocaleString('en')} bytes`);
    showStatus(statusName);
    if (scene.models.length === 0) return;
    renderer?.setModels(scene.models);
    if (!cameraMoved)
      camera.distance = framingDistance(camera, scene.models, canvas.clientWidth || 1, canvas.clientHeight || 1);
    state.models = scene.models.length;
    state.level = scene.models[0].detailLevel;
    state.levels.push({ bytes: size, level: state.level });
    state.names = scene.models.map((m) => m.name);
    if (scene.models.length > 1) slider.hidden = false;
    showStatus(statusName);
    redraw();
  }).finally(() => {
    inFlight = null;
    if (again) { again = false; refine(source, layout); }
  });
}

/// Waits until every byte received so far has been decoded and shown.
async function settle(source, layout) {
  refine(source, layout);
  while (inFlight) {
    await inFlight;
    refine(source, layout);
  }
}

async function stream(url) {
  const decoder = await createDecoder();
  const source = new SceneSource(decoder);
  const name = statusName = `${url.split('/').pop()}: `;
  let layout = null;
  const onBytes = (bytes) => {
    source.push(bytes);
    state.bytes = decoder.size;
    showStatus(name);
    refine(source, layout);
  };
  try {
    // header, then manifest (a server without Range sends everything at the first request)
    let whole = await fetchRange(url, decoder, 0, 20, onBytes);
    if (!whole && decoder.size >= 20) {
      let needed;
      try { needed = decoder.needed(); decoder.layout(); } catch (e) { if (!(e instanceof GeomipError)) throw e; }
      if (needed > decoder.size) whole = await fetchRange(url, decoder, decoder.size, needed, onBytes);
    }
    try {
      layout = decoder.layout();
    } catch (e) {
      if (!(e instanceof GeomipError)) throw e;
      throw new StreamError(`${url} is not a geomip pack (${e.message.replace(/^geomip: /, '')})`);
    }
    if (!layout)
      throw new StreamError(`${url} ended after ${decoder.size} bytes, inside the pack's header or manifest`);
    state.fileSize = layout.fileSize;
    const numModels = layout.chunks.reduce((n, c) => Math.max(n, c.model + 1), 0);
    for (const name of ['from', 'to'])
      if (params.has(name) && Number(params.get(name)) >= numModels)
        throw new UsageError(
            `${name}=${params.get(name)}: the pack has ${numModels} model${numModels === 1 ? '' : 's'}`);
    const limit = packLimit = limitFor(layout);
    let span = Number(params.get('first') ?? 16384);
    while (!whole && decoder.size < limit && !corrupt) {
      const begin = decoder.size, end = Math.min(limit, begin + span);
      whole = await fetchRange(url, decoder, begin, end, onBytes);
      if (!whole && decoder.size < end)
        throw new StreamError(`the stream of ${url} ended at ${decoder.size.toLocaleString('en')} of ` +
                              `${layout.fileSize.toLocaleString('en')} bytes`);
      span *= 2;
    }
    state.bytes = decoder.size;
    if (corrupt) {
      await settle(source, layout);
      throw corrupt;
    }
    if (decoder.size < layout.fileSize && stopAt === null)
      throw new StreamError(`the stream of ${url} ended at ${decoder.size.toLocaleString('en')} of ` +
                            `${layout.fileSize.toLocaleString('en')} bytes`);
    await settle(source, layout);
    if (corrupt) throw corrupt;
    showStatus(name);
    state.phase = 'done';
    redraw();
  } catch (e) {
    state.bytes = decoder.size;
    try { await settle(source, layout); } catch (_) { /* the error below is the one to show */ }
    showStatus(name);
    if (e instanceof UsageError)
      fail(e.message);
    else if (e instanceof StreamError)
      fail(`${e.message}; showing ${state.level >= 0 ? `level ${state.level}` : 'nothing'}`);
    else fail(`error: ${e.message}`);
  }
}

const pack = params.get('pack');
let packUrl = null;
try {
  if (pack) packUrl = new URL(pack, location.href).href;
} catch (_) {
  fail(`pack=${pack} is not a URL`);
}
const badParam = checkParams();
if (!pack) fail('no pack given: open index.html?pack=URL');
else if (badParam)
  fail(badParam);
else if (renderer && packUrl)
  stream(packUrl);
