// The web viewer in headless Chromium (WebGL2 on SwiftShader), served by stock nginx with the repo's config
// (web/nginx.conf: Range + CORS) and by a throttled Python server (cors_range_server.py), on free ports of
// 127.0.0.1. Checks, on images read back from the page's canvas (properties, never golden pixels):
//  - a stall after 5 % of the bytes, or after the first prefix that holds a model when that is later (≤ 7 %:
//    format 4's first CRC group): a coarse model is on screen (level ≥ 0, pixels cover ≥ 1 % of the view);
//  - streamed to the end through the throttled server: the page refined several times, coarse to fine, and
//    the final image covers the decoded mesh's projected silhouette (computed here from the WASM decode of
//    the same pack with the page's camera: ≥ 97 % of the silhouette's pixels drawn, ≤ 2 % of the drawn
//    pixels outside it, dilated by 2 px);
//  - the default camera frames the model as geomip-view does: the drawn silhouette's bounding box spans 60–80 %
//    of the canvas height (bunny; horse of the horse–pig pack), and the horse stands upright (the pack's
//    frame maps its data's +z to the page's +y; from the side it is longer than tall);
//  - through nginx, cross-origin: every request was a Range request answered 206;
//  - a morph at t = 0.5 differs from both ends (and the ends from each other); the wavelet schedule's
//    midpoint differs from the linear one, its t = 0 does not;
//  - a mouse drag turns the model, the wheel and a two-finger pinch (touch events) zoom out and in;
//  - the three.js example page (web/three/example.html) draws the loaded model;
//  - a 404, an unreachable server, a file that is not a pack, a server killed mid-stream, a corrupt chunk:
//    phase 'error' with one line, and (the last two) the last good level still drawn.
//   node browser_test.mjs NGINX_CONF OUT_DIR
// Screenshots go to OUT_DIR for people. Needs chromium, nginx, python3 and npm's puppeteer-core.
import { spawn, spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync, writeFileSync, rmSync } from 'node:fs';
import net from 'node:net';
import zlib from 'node:zlib';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import puppeteer from 'puppeteer-core';
import { createDecoder } from '../../web/geomip.js';
import { viewProjection, kBackground } from '../../web/renderer.js';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, '../..');
const [nginxConf = path.join(root, 'web/nginx.conf'), outDir = path.join(root, 'build/web-test')] =
  process.argv.slice(2);
mkdirSync(outDir, { recursive: true });
const W = 640, H = 480;
const bunny = 'tests/data/web-bunny-l4.gip', horsePig = 'tests/data/web-horse-pig-l4.gip';

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) ++failures;
}

function freePort() {
  return new Promise((resolve, reject) => {
    const s = net.createServer();
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => resolve(port)); });
    s.on('error', reject);
  });
}

// ---- servers -------------------------------------------------------------------------------------------
const children = [];
const tmp = mkdtempSync(path.join(os.tmpdir(), 'geomip-web-'));
async function startNginx() {
  for (let attempt = 0; attempt < 5; ++attempt) {  // a port taken between probe and bind: try another
    const port = await freePort();
    const prefix = path.join(tmp, `nginx-${port}`);
    mkdirSync(prefix, { recursive: true });
    const conf = readFileSync(nginxConf, 'utf8').replaceAll('@PREFIX@', prefix).replaceAll('@PORT@', String(port))
        .replaceAll('@ROOT@', root);
    writeFileSync(path.join(prefix, 'nginx.conf'), conf);
    // as root (CI), nginx's workers would switch to `nobody`, who may not read the checkout: stay root
    const globals = `daemon off;${process.getuid?.() === 0 ? ' user root;' : ''}`;
    const child = spawn('nginx', ['-p', prefix, '-c', path.join(prefix, 'nginx.conf'), '-g', globals],
                        { stdio: ['ignore', 'ignore', 'pipe'] });
    children.push(child);
    let stderr = '';
    child.stderr.on('data', (d) => { stderr += d; });
    for (let k = 0; k < 50; ++k) {
      if (child.exitCode !== null) break;
      const ok = await new Promise((resolve) => {
        const c = net.connect(port, '127.0.0.1', () => { c.end(); resolve(true); });
        c.on('error', () => resolve(false));
      });
      if (ok) return port;
      await new Promise((r) => setTimeout(r, 100));
    }
    child.kill();
    console.log(`nginx on port ${port} did not start: ${stderr.trim()}`);
  }
  throw new Error('nginx did not start');
}

function startRangeServer(...args) {  // serves the repository; '--root DIR' first serves DIR instead
  const rootArgs = args[0] === '--root' ? args.splice(0, 2) : ['--root', root];
  return new Promise((resolve, reject) => {
    const child = spawn('python3', [path.join(here, 'cors_range_server.py'), ...rootArgs, ...args],
                        { stdio: ['ignore', 'pipe', 'inherit'] });
    children.push(child);
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/PORT (\d+)/);
      if (m) resolve(Number(m[1]));
    });
    child.on('exit', () => reject(new Error('range server exited')));
  });
}

// ---- images --------------------------------------------------------------------------------------------
async function canvasPixels(page) {  // RGBA, top row first
  const b64 = await page.evaluate(() => {
    const canvas = document.getElementById('view');
    const gl = canvas.getContext('webgl2');
    const px = new Uint8Array(canvas.width * canvas.height * 4);
    gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let s = '';
    for (let i = 0; i < px.length; i += 0x8000) s += String.fromCharCode(...px.subarray(i, i + 0x8000));
    return [canvas.width, canvas.height, btoa(s)];
  });
  const [w, h, data] = b64;
  const raw = Buffer.from(data, 'base64');
  const out = new Uint8Array(raw.length);
  for (let y = 0; y < h; ++y) out.set(raw.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
  return { w, h, px: out };
}
function drawnMask({ w, h, px }) {  // pixels that are not the background
  const m = new Uint8Array(w * h);
  for (let i = 0; i < w * h; ++i) {
    const d = Math.abs(px[4 * i] - kBackground[0]) + Math.abs(px[4 * i + 1] - kBackground[1]) +
              Math.abs(px[4 * i + 2] - kBackground[2]);
    m[i] = d > 12 ? 1 : 0;
  }
  return m;
}
const count = (m) => m.reduce((a, b) => a + b, 0);
function differing(a, b) {
  let n = 0;
  for (let i = 0; i < a.px.length; i += 4)
    if (Math.abs(a.px[i] - b.px[i]) + Math.abs(a.px[i + 1] - b.px[i + 1]) + Math.abs(a.px[i + 2] - b.px[i + 2]) > 24) ++n;
  return n / (a.w * a.h);
}

/// A PNG (8-bit RGB or RGBA, not interlaced: what Chromium's screenshots are) as RGBA, top row first.
function decodePng(png) {
  let at = 8, w = 0, h = 0, channels = 0;
  const idat = [];
  while (at < png.length) {
    const len = png.readUInt32BE(at), type = png.toString('latin1', at + 4, at + 8);
    const data = png.subarray(at + 8, at + 8 + len);
    if (type === 'IHDR') {
      w = data.readUInt32BE(0); h = data.readUInt32BE(4);
      if (data[8] !== 8 || data[12] !== 0 || ![2, 6].includes(data[9])) throw new Error('PNG: not 8-bit RGB(A)');
      channels = data[9] === 6 ? 4 : 3;
    } else if (type === 'IDAT') idat.push(data);
    at += 12 + len;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = w * channels, cur = new Uint8Array(stride), px = new Uint8Array(w * h * 4);
  let prev = new Uint8Array(stride);
  for (let y = 0; y < h; ++y) {
    const f = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; ++i) {
      const a = i >= channels ? cur[i - channels] : 0, b = prev[i], c = i >= channels ? prev[i - channels] : 0;
      const pred = f === 1 ? a : f === 2 ? b : f === 3 ? (a + b) >> 1 :
        f === 4 ? (Math.abs(b - c) <= Math.abs(a - c) && Math.abs(b - c) <= Math.abs(a + b - 2 * c) ? (Math.abs(a + b - 2 * c) < Math.abs(b - c) ? c : b) : a) : 0;
      cur[i] = (line[i] + pred) & 255;
    }
    for (let x = 0; x < w; ++x)
      for (let c = 0; c < 3; ++c) px[(y * w + x) * 4 + c] = cur[x * channels + c];
    prev = Uint8Array.from(cur);
  }
  return { w, h, px };
}

/// The decoded mesh's projected silhouette: every grid triangle of model 0 (hole-masked quads left out),
/// normalized as the page draws it (GeomipDecoder.scene), projected with the page's camera (its state after
/// the load: the distance that framed the model), rasterized.
async function silhouette(packPath, w, h, camera) {
  const decoder = await createDecoder();
  decoder.push(readFileSync(path.join(root, packPath)));
  const m = decoder.scene().models[0];
  const { matrix } = viewProjection(camera, w, h);
  const size = (1 << m.level) + 1;
  const mask = new Uint8Array(w * h);
  const project = (p, k) => {
    const x = m.positions[(p * size * size + k) * 3], y = m.positions[(p * size * size + k) * 3 + 1],
      z = m.positions[(p * size * size + k) * 3 + 2];
    const cx = matrix[0] * x + matrix[4] * y + matrix[8] * z + matrix[12];
    const cy = matrix[1] * x + matrix[5] * y + matrix[9] * z + matrix[13];
    const cw = matrix[3] * x + matrix[7] * y + matrix[11] * z + matrix[15];
    return [(cx / cw + 1) / 2 * w, (1 - cy / cw) / 2 * h];
  };
  const tri = (a, b, c) => {
    const x0 = Math.max(0, Math.floor(Math.min(a[0], b[0], c[0]))), x1 = Math.min(w - 1, Math.ceil(Math.max(a[0], b[0], c[0])));
    const y0 = Math.max(0, Math.floor(Math.min(a[1], b[1], c[1]))), y1 = Math.min(h - 1, Math.ceil(Math.max(a[1], b[1], c[1])));
    const e = (p, q, x, y) => (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
    const area = e(a, b, c[0], c[1]);
    if (Math.abs(area) < 1e-12) return;
    for (let y = y0; y <= y1; ++y)
      for (let x = x0; x <= x1; ++x) {
        const px = x + 0.5, py = y + 0.5;
        const w0 = e(b, c, px, py) / area, w1 = e(c, a, px, py) / area, w2 = e(a, b, px, py) / area;
        if (w0 >= 0 && w1 >= 0 && w2 >= 0) mask[y * w + x] = 1;
      }
  };
  const holeRes = m.holeLevel >= 0 ? 1 << m.holeLevel : 0;
  for (let p = 0; p < m.numPatches; ++p)
    for (let j = 0; j + 1 < size; ++j)
      for (let i = 0; i + 1 < size; ++i) {
        if (holeRes) {  // the shader's rule: the quad of the hole mask under the fragment's (u,v)
          const q = (Math.min(holeRes - 1, Math.floor((j + 0.5) / (size - 1) * holeRes)) * holeRes +
                     Math.min(holeRes - 1, Math.floor((i + 0.5) / (size - 1) * holeRes)));
          if (m.holes[p * holeRes * holeRes + q]) continue;
        }
        const v00 = project(p, j * size + i), v10 = project(p, j * size + i + 1);
        const v01 = project(p, (j + 1) * size + i), v11 = project(p, (j + 1) * size + i + 1);
        // The page's split (and geomip decode's): the shorter diagonal; corner quads and ties by i + j + p.
        const at = (k) => [0, 1, 2].map((c) => m.positions[(p * size * size + k) * 3 + c]);
        const d2 = (u, v) => { const a = at(u), b = at(v); return (a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2; };
        let ac = (i + j + p) % 2 === 0;
        if (!((i === 0 || i === size - 2) && (j === 0 || j === size - 2))) {
          const diff = d2(j * size + i, (j + 1) * size + i + 1) - d2(j * size + i + 1, (j + 1) * size + i);
          if (diff < 0) ac = true;
          if (diff > 0) ac = false;
        }
        if (ac) { tri(v00, v10, v11); tri(v00, v11, v01); } else { tri(v00, v10, v01); tri(v10, v11, v01); }
      }
  decoder.dispose();
  return mask;
}
function dilate(mask, w, h, r) {
  const out = new Uint8Array(w * h);
  for (let y = 0; y < h; ++y)
    for (let x = 0; x < w; ++x) {
      if (!mask[y * w + x]) continue;
      for (let dy = -r; dy <= r; ++dy)
        for (let dx = -r; dx <= r; ++dx) {
          const xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < w && yy < h) out[yy * w + xx] = 1;
        }
    }
  return out;
}

/// Rows and columns [y0, y1] × [x0, x1] of a mask's set pixels, and the fractions of the image they span.
function boundingBox(mask, w, h) {
  let x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (let y = 0; y < h; ++y)
    for (let x = 0; x < w; ++x)
      if (mask[y * w + x]) { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); }
  return { x0, x1, y0, y1, height: (y1 - y0 + 1) / h, width: (x1 - x0 + 1) / w };
}
/// The default camera frames the model as geomip-view does: the drawn silhouette's bounding box spans 60–80 %
/// of the canvas height and touches no edge. Returns the box.
function checkFramed(img, what) {
  const b = boundingBox(drawnMask(img), img.w, img.h);
  check(b.height >= 0.6 && b.height <= 0.8 && b.x0 > 0 && b.y0 > 0 && b.x1 < img.w - 1 && b.y1 < img.h - 1,
        `${what}: the silhouette spans ${(100 * b.height).toFixed(1)} % of the height (60–80 %) and ` +
        `${(100 * b.width).toFixed(1)} % of the width, inside the canvas`);
  return b;
}

// ---- the page ------------------------------------------------------------------------------------------
let browser;
async function open(url, { until = (s) => s.phase !== 'loading', timeout = 120000 } = {}) {
  const page = await browser.newPage();
  await page.setViewport({ width: W, height: H, deviceScaleFactor: 1 });
  page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
  await page.goto(url);
  await page.waitForFunction(`(${until.toString()})(window.geomipViewer ?? { phase: 'loading' })`,
                             { timeout, polling: 50 });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  return page;
}
const stateOf = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.geomipViewer)));

try {
  const nginx = await startNginx();
  const bunnyBytes = readFileSync(path.join(root, bunny)).length;
  // The first prefix whose scene has a model (WASM decode, complete chunks only; bisection): formats 4 and 5
  // verify chunks by CRC groups of 256 B, so the coarse levels arrive with the first group's trailer (590 of
  // the format-4 bunny's 8,865 bytes; format 3's per-chunk CRCs gave them within 5 %).
  const firstShown = await (async () => {
    const whole = readFileSync(path.join(root, bunny));
    const shows = async (n) => {
      const d = await createDecoder();
      d.push(whole.subarray(0, n));
      let models = 0;
      try { models = d.scene().models.length; } catch (_) { /* too short for the manifest */ }
      d.dispose();
      return models > 0;
    };
    let lo = 0, hi = whole.length;  // shows(hi), !shows(lo)
    while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (await shows(mid)) hi = mid; else lo = mid; }
    return hi;
  })();
  // Format 11 (two-layer normal maps): 604 of 7,578 bytes — the manifest holds layer 2's codec header, and the
  // normal maps shrank the pack by a fifth (format 10: 9,312 bytes).
  const stallAt = Math.max(Math.floor(bunnyBytes * 0.05), firstShown);
  check(stallAt <= bunnyBytes * 0.085, `the first model needs ${firstShown} of ${bunnyBytes} bytes (≤ 8.5 %); the stall comes after ${stallAt}`);
  const stalled = await startRangeServer('--rate', '20000', '--stall-after', String(stallAt), '--stall-seconds', '60');
  const throttled = await startRangeServer('--rate', '3000');
  const killed = await startRangeServer('--die-after', String(Math.floor(bunnyBytes * 0.4)));
  // a copy of the bunny pack with one byte flipped at 60 % of the file (inside a chunk: its CRC fails)
  const damaged = Buffer.from(readFileSync(path.join(root, bunny)));
  damaged[Math.floor(bunnyBytes * 0.6)] ^= 0x5a;
  mkdirSync(path.join(tmp, 'damaged'));
  writeFileSync(path.join(tmp, 'damaged', 'bunny.gip'), damaged);
  // and one with a byte flipped in its first chunk (no level to show: the page must still say why)
  const firstChunk = await (async () => {
    const d = await createDecoder();
    d.push(readFileSync(path.join(root, bunny)));
    const at = d.layout().manifestEnd;
    d.dispose();
    return at;
  })();
  const damagedFirst = Buffer.from(readFileSync(path.join(root, bunny)));
  damagedFirst[firstChunk + 1] ^= 0x5a;
  writeFileSync(path.join(tmp, 'damaged', 'first.gip'), damagedFirst);
  const damagedServer = await startRangeServer('--root', path.join(tmp, 'damaged'));
  const endless = await startRangeServer('--no-ranges', '--endless');
  const stallsEarly = await startRangeServer('--stall-after', '2000', '--stall-seconds', '30');
  browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', headless: true,
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-dev-shm-usage',
           `--window-size=${W},${H}`],
  });
  const pageUrl = (pack, extra = '') => `http://127.0.0.1:${nginx}/web/index.html?hud=0&pack=${encodeURIComponent(pack)}${extra}`;
  const area = W * H;

  // 1. a stall after 5 % of the bytes: the coarse model
  let coarse = null;
  {
    const page = await open(pageUrl(`http://127.0.0.1:${stalled}/${bunny}`), { until: (s) => s.models > 0 });
    const s = await stateOf(page);
    const img = coarse = await canvasPixels(page);
    await page.screenshot({ path: path.join(outDir, 'bunny-5-percent.png') });
    const drawn = count(drawnMask(img)) / area;
    check(s.bytes <= stallAt && s.level >= 0,
          `after ${s.bytes} of ${bunnyBytes} bytes (≤ ${stallAt}) the page shows level ${s.level}`);
    check(drawn >= 0.01, `the coarse model covers ${(100 * drawn).toFixed(1)} % of the view (≥ 1 %)`);
    await page.close();
  }
  // 2. throttled to the end: refinements coarse → fine, the final image covers the silhouette
  {
    // The first request 2 KB (format 11's bunny is 7,578 bytes: after 4 KB too little was left to stream).
    const page = await open(pageUrl(`http://127.0.0.1:${throttled}/${bunny}`, '&first=2048'));
    const s = await stateOf(page);
    const img = await canvasPixels(page);
    await page.screenshot({ path: path.join(outDir, 'bunny-final.png') });
    const levels = s.levels.map((l) => l.level);
    check(s.phase === 'done' && s.bytes === bunnyBytes, `throttled stream done: ${s.bytes} bytes, phase ${s.phase}`);
    const bytes = s.levels.map((l) => l.bytes);
    check(s.levels.length >= 3 && levels.every((l, i) => i === 0 || l >= levels[i - 1]) && levels.at(-1) === 4 &&
          bytes.every((b, i) => i === 0 || b > bytes[i - 1]),
          `refined in place ${s.levels.length} times, at ${bytes.join(', ')} bytes (levels ${levels.join(', ')})`);
    const change = differing(coarse, img);
    check(change >= 0.005, `the final image differs from the 5 % one in ${(100 * change).toFixed(2)} % of the pixels`);
    const sil = await silhouette(bunny, img.w, img.h, s.camera);
    const drawn = drawnMask(img);
    let covered = 0, outside = 0;
    const grown = dilate(sil, img.w, img.h, 2);
    for (let i = 0; i < sil.length; ++i) {
      if (sil[i] && drawn[i]) ++covered;
      if (drawn[i] && !grown[i]) ++outside;
    }
    const silN = count(sil), drawnN = count(drawn);
    check(silN > 0.02 * area, `the silhouette covers ${(100 * silN / area).toFixed(1)} % of the view`);
    check(covered >= 0.97 * silN, `the final image covers ${(100 * covered / silN).toFixed(2)} % of the projected silhouette (≥ 97 %)`);
    check(outside <= 0.02 * drawnN, `${(100 * outside / Math.max(drawnN, 1)).toFixed(2)} % of the drawn pixels lie outside it (≤ 2 %)`);
    checkFramed(img, 'bunny, default camera');
    await page.close();
  }
  // 3. nginx, cross-origin (page on 127.0.0.1, pack on localhost): Range requests, 206 each
  {
    const page = await open(pageUrl(`http://localhost:${nginx}/${bunny}`, '&first=1024'));
    const s = await stateOf(page);
    check(s.phase === 'done' && s.bytes === bunnyBytes, `nginx cross-origin: ${s.bytes} bytes, phase ${s.phase} ${s.message}`);
    check(s.requests.length >= 4 && s.requests.every((r) => r.status === 206),
          `nginx answered ${s.requests.length} Range requests with ${[...new Set(s.requests.map((r) => r.status))].join(',')}`);
    await page.close();
  }
  // 4. morph at t = 0.5 differs from both ends
  {
    const images = [];
    for (const t of [0, 0.5, 1]) {
      const page = await open(pageUrl(`/${horsePig}`, `&morph=${t}`));
      const s = await stateOf(page);
      check(s.phase === 'done' && s.models === 2, `horse–pig at t = ${t}: ${s.models} models, phase ${s.phase}`);
      images.push(await canvasPixels(page));
      await page.screenshot({ path: path.join(outDir, `morph-${t}.png`) });
      if (t === 0) {
        // The horse (model 0) upright: the pack's frame turns its data's up (+z) into the page's +y, and
        // from the side it is longer than tall (on its data's y up it stood on its tail, taller than long).
        const decoder = await createDecoder();
        decoder.push(readFileSync(path.join(root, horsePig)));
        const n = decoder.decode({ normals: false }).models[0].normalization;
        decoder.dispose();
        const scale = Math.hypot(n[4], n[5], n[6]);
        check(scale > 0 && Math.abs(n[4]) < 1e-9 && Math.abs(n[5]) < 1e-9 && Math.abs(n[6] / scale - 1) < 1e-9,
              `horse–pig: the pack's frame shows the horse's +z as up (row 1: ${[n[4], n[5], n[6]].map((v) => v.toFixed(3)).join(', ')})`);
        const b = checkFramed(images[0], 'horse, default camera');
        check(b.width * W > b.height * H, `horse: upright, its silhouette ${Math.round(b.width * W)} px wide, ${Math.round(b.height * H)} px tall`);
      }
      await page.close();
    }
    const d0 = differing(images[1], images[0]), d1 = differing(images[1], images[2]), ends = differing(images[0], images[2]);
    check(d0 >= 0.005 && d1 >= 0.005 && ends >= 0.005,
          `t = 0.5 differs from t = 0 in ${(100 * d0).toFixed(2)} %, from t = 1 in ${(100 * d1).toFixed(2)} % of the pixels (ends: ${(100 * ends).toFixed(2)} %)`);
    // the wavelet schedule (4 bands): its midpoint is not the linear one; its ends are the models themselves
    const wavelet = [];
    for (const t of [0, 0.5]) {
      const page = await open(pageUrl(`/${horsePig}`, `&morph=${t}&schedule=wavelet`));
      const s = await stateOf(page);
      check(s.phase === 'done' && s.models === 2, `horse–pig, wavelet schedule, t = ${t}: phase ${s.phase}`);
      wavelet.push(await canvasPixels(page));
      await page.screenshot({ path: path.join(outDir, `morph-wavelet-${t}.png`) });
      await page.close();
    }
    const w0 = differing(wavelet[0], images[0]), wl = differing(wavelet[1], images[1]);
    check(w0 <= 0.002 && wl >= 0.002,
          `wavelet schedule: t = 0 as linear t = 0 (${(100 * w0).toFixed(2)} % differ), t = 0.5 differs from linear t = 0.5 in ${(100 * wl).toFixed(2)} %`);
  }
  // 5. orbit and zoom: a mouse drag turns the model, the wheel zooms out, a two-finger pinch zooms in
  {
    const page = await open(pageUrl(`/${bunny}`));
    const camera = () => page.evaluate(() => ({ ...window.geomipViewer.camera, draws: window.geomipViewer.draws }));
    const frame = async (before) => {  // the next drawn frame's pixels
      await page.waitForFunction((n) => window.geomipViewer.draws > n, { timeout: 10000, polling: 20 }, before.draws);
      return canvasPixels(page);
    };
    const c0 = await camera(), img0 = await canvasPixels(page);
    await page.mouse.move(W / 2, H / 2);
    await page.mouse.down();
    await page.mouse.move(W / 2 + 120, H / 2 + 30, { steps: 6 });
    await page.mouse.up();
    const img1 = await frame(c0), c1 = await camera();
    check(Math.abs(c1.yaw - c0.yaw) > 0.5 && differing(img0, img1) >= 0.01,
          `mouse drag: yaw ${c0.yaw.toFixed(2)} → ${c1.yaw.toFixed(2)}, ${(100 * differing(img0, img1)).toFixed(1)} % of the pixels changed`);
    await page.mouse.wheel({ deltaY: 400 });
    const img2 = await frame(c1), c2 = await camera();
    const cover = (img) => count(drawnMask(img)) / area;
    check(c2.distance > c1.distance && cover(img2) < cover(img1),
          `wheel: distance ${c1.distance.toFixed(2)} → ${c2.distance.toFixed(2)}, coverage ${(100 * cover(img1)).toFixed(1)} → ${(100 * cover(img2)).toFixed(1)} %`);
    const cdp = await page.createCDPSession();
    const touch = (type, points) => cdp.send('Input.dispatchTouchEvent', {
      type, touchPoints: points.map(([x, y], id) => ({ x, y, id, radiusX: 1, radiusY: 1, force: 1 })) });
    await touch('touchStart', [[W / 2 - 40, H / 2], [W / 2 + 40, H / 2]]);
    for (let k = 1; k <= 6; ++k) await touch('touchMove', [[W / 2 - 40 - 20 * k, H / 2], [W / 2 + 40 + 20 * k, H / 2]]);
    await touch('touchEnd', []);
    const img3 = await frame(c2), c3 = await camera();
    check(c3.distance < c2.distance && cover(img3) > cover(img2),
          `two-finger pinch: distance ${c2.distance.toFixed(2)} → ${c3.distance.toFixed(2)}, coverage ${(100 * cover(img2)).toFixed(1)} → ${(100 * cover(img3)).toFixed(1)} %`);
    await page.close();
  }
  // 6. the three.js example (web/three/example.html, three from node_modules through nginx): a model drawn
  {
    const page = await browser.newPage();
    await page.setViewport({ width: W, height: H, deviceScaleFactor: 1 });
    page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
    await page.goto(`http://127.0.0.1:${nginx}/web/three/example.html?pack=${encodeURIComponent(`/${bunny}`)}`);
    const all = bunnyBytes.toLocaleString('en');
    await page.waitForFunction((b) => document.getElementById('info').textContent.includes(`${b} of ${b} bytes`),
                               { timeout: 60000, polling: 50 }, all);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const shot = decodePng(Buffer.from(await page.screenshot({ path: path.join(outDir, 'three-example.png') })));
    const drawn = count(drawnMask(shot)) / (shot.w * shot.h);
    check(drawn >= 0.03, `three.js example: the loaded model covers ${(100 * drawn).toFixed(1)} % of the view`);
    await page.close();
  }
  // 7. errors: one line, the last good level kept
  const errorCases = [
    ['a 404', `/tests/data/no-such-pack.gip`, /HTTP 404/, false],
    ['an unreachable server', `http://127.0.0.1:${await freePort()}/x.gip`, /cannot fetch/, false],
    ['a file that is not a pack', `/web/index.html`, /not a geomip pack/, false],
    ['a server killed mid-stream', `http://127.0.0.1:${killed}/${bunny}`, /ended at|broke off/, true],
    ['a corrupt chunk', `http://127.0.0.1:${damagedServer}/bunny.gip`, /corrupt \(CRC\)/, true],
    ['a corrupt first chunk', `http://127.0.0.1:${damagedServer}/first.gip`, /corrupt \(CRC\).*showing nothing/, false],
    ['a server that stalls (timeout=2)', `http://127.0.0.1:${stallsEarly}/${bunny}`, /sent nothing for 2 s/, true, '&timeout=2'],
    ['a pack URL that is no URL', 'http://[bad', /is not a URL/, false],
    ['morph=abc', `/${bunny}`, /^morph=abc: a morph time in \[0, 1\]$/, false, '&morph=abc'],
    ['from=5 on a one-model pack', `/${bunny}`, /^from=5: the pack has 1 model$/, false, '&from=5'],
  ];
  for (const [what, pack, pattern, keeps, extra = ''] of errorCases) {
    // small ranges, so that complete responses arrive before the server dies (a browser may drop the
    // bytes of a response that breaks off)
    const page = await open(pageUrl(pack, `&first=1024${extra}`));
    const s = await stateOf(page);
    const line = await page.evaluate(() => document.getElementById('error').textContent);
    const drawn = count(drawnMask(await canvasPixels(page))) / area;
    check(s.phase === 'error' && pattern.test(line) && !line.includes('\n'), `${what}: "${line}"`);
    if (keeps) check(s.level >= 0 && drawn >= 0.01, `${what}: level ${s.level} still drawn (${(100 * drawn).toFixed(1)} % of the view)`);
    await page.close();
  }
  // 8. a server without Range whose body never ends: read up to the pack's size, then shown whole
  {
    const page = await open(pageUrl(`http://127.0.0.1:${endless}/${bunny}`));
    const s = await stateOf(page);
    check(s.phase === 'done' && s.bytes === bunnyBytes && s.requests.length === 1,
          `no Range, an endless body: ${s.phase}, ${s.bytes} of ${bunnyBytes} bytes read in ${s.requests.length} request(s)`);
    await page.close();
  }
} catch (e) {
  console.log(`FAIL ${e.stack ?? e}`);
  ++failures;
} finally {
  await browser?.close();
  for (const c of children) c.kill();
  rmSync(tmp, { recursive: true, force: true });
}
console.log(failures === 0 ? 'browser_test: all checks passed' : `browser_test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
