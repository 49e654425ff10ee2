// geomip.js — the .gip decoder for JavaScript (browsers, workers, node): an ES module over the WASM build of
// codec/ (dist/geomip-core.{js,wasm}, built by scripts/build-wasm).
//
//   import { createDecoder } from './geomip.js';
//   const decoder = await createDecoder();
//   decoder.push(bytes);                 // Uint8Array: the next bytes of the file, in order, as they arrive
//   decoder.layout();                    // null until header + manifest are in; then the chunk table
//   const { status, models } = decoder.decode();   // the best grids these bytes give, per model
//   decoder.scene({ bands: 1 });         // the same as normalized scene models (what the viewer draws)
//   decoder.dispose();
//
// decode() returns per model `geometry` (one Float32Array per patch: (2^level+1)² xyz samples, row-major, in
// model units), `normals` (same layout at the normal-map level, or []), `holeMask` (one Uint8Array per patch,
// 4^L bytes, 1 = quad left out; [] = no holes) — bit-identical to the native codec::decode_pack
// (tests/web/wasm_decoder_test.mjs checks every byte prefix). Arrays are copies: they stay valid after
// further push()/decode() calls. Each decode() decodes the bytes received since the last one (the codec's
// incremental PackDecoder) and rebuilds the grids; status is 'ok' (every chunk), 'truncated' (more bytes to come: models hold what the prefix
// gives, none before the manifest), 'corrupt' (CRC or impossible bytes: models hold the last good level) or
// 'unsupported-version'.

const kStatus = ['ok', 'truncated', 'corrupt', 'unsupported-version', 'invalid-argument'];
const kKind = ['geometry', 'normals', 'hole-mask'];

let corePromise = null;

/// Loads the WASM module once per page (or node process). `options.coreUrl` overrides where
/// geomip-core.js comes from (default: dist/ beside this file); the .wasm is read beside it, or taken from
/// `options.wasmBinary` (an ArrayBuffer/Uint8Array). Under node the .wasm is read from disk (the Emscripten
/// build targets web and workers only: its node path is not an ES module).
export function loadCore(options = {}) {
  if (!corePromise) {
    const coreUrl = options.coreUrl ?? new URL('./dist/geomip-core.js', import.meta.url).href;
    corePromise = (async () => {
      let wasmBinary = options.wasmBinary;
      if (!wasmBinary && typeof process === 'object' && process.versions?.node) {
        const { readFile } = await import('node:fs/promises');
        wasmBinary = await readFile(new URL(coreUrl.replace(/\.js$/, '.wasm')));
      }
      const factory = (await import(coreUrl)).default;
      return factory(wasmBinary ? { wasmBinary } : {});
    })();
  }
  return corePromise;
}

export async function createDecoder(options = {}) {
  return new GeomipDecoder(await loadCore(options));
}

export class GeomipDecoder {
  constructor(core) {
    this.core_ = core;
    this.handle_ = core._gip_create();
  }

  /// Appends the next bytes of the file (a Uint8Array, another typed array or DataView, or an ArrayBuffer).
  push(bytes) {
    this.check_();
    // Bytes only: `new Uint8Array(123)` would append 123 zero bytes, and a string or null pushed nothing.
    if (!(bytes instanceof ArrayBuffer) && !ArrayBuffer.isView(bytes))
      throw new GeomipError('invalid-argument', 'push() takes a Uint8Array, another typed array, a DataView or ' +
                            `an ArrayBuffer, not ${bytes === null ? 'null' : typeof bytes}`);
    const view = bytes instanceof Uint8Array ? bytes :
        ArrayBuffer.isView(bytes) ? new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength) :
                                    new Uint8Array(bytes);
    if (view.length === 0) return;
    const at = this.core_._gip_reserve(this.handle_, view.length);
    if (at === 0) throw new RangeError('geomip: more than 2 GiB pushed');
    this.core_.HEAPU8.set(view, at);
    this.core_._gip_commit(this.handle_, view.length, view.length);
  }

  /// Bytes received so far (0 after dispose()).
  get size() { return this.handle_ ? this.core_._gip_size(this.handle_) : 0; }

  check_() {
    if (!this.handle_) throw new GeomipError('invalid-argument', 'this decoder was disposed');
  }

  /// Bytes the header/manifest need before layout() can answer (20, then where the manifest ends).
  needed() {
    this.check_();
    return this.core_._gip_needed(this.handle_);
  }

  /// The pack's layout once header + manifest have arrived: { manifestEnd, fileSize, chunks: [{ model, kind,
  /// pass, offset, size }] }; null while they have not; throws GeomipError when they are not a pack's.
  layout() {
    this.check_();
    const c = this.core_, h = this.handle_;
    const status = kStatus[c._gip_read_info(h)];
    if (status === 'truncated') return null;
    if (status !== 'ok') throw new GeomipError(status, statusMessage(c, status));
    const chunks = [];
    for (let i = 0, n = c._gip_num_chunks(h); i < n; ++i) {
      chunks.push({
        model: c._gip_chunk(h, i, 0), kind: kKind[c._gip_chunk(h, i, 1)], pass: c._gip_chunk(h, i, 2),
        offset: c._gip_chunk(h, i, 3), size: c._gip_chunk(h, i, 4),
      });
    }
    return { manifestEnd: c._gip_manifest_end(h), fileSize: c._gip_file_size(h), chunks };
  }

  /// Decodes every byte received so far into grids (see the top of this file). options.normals (default
  /// true): decode the normal maps too.
  decode(options = {}) {
    this.check_();
    const c = this.core_, h = this.handle_;
    const status = kStatus[c._gip_decode(h, options.normals === false ? 0 : 1)];
    const models = [];
    for (let m = 0, n = c._gip_num_models(h); m < n; ++m) {
      const patches = c._gip_model_field(h, m, 0);
      const level = c._gip_model_field(h, m, 1);
      const normalLevel = c._gip_model_field(h, m, 2);
      const holeLevel = c._gip_model_field(h, m, 3);
      const grid = (p, what, lvl) => {
        const side = (1 << lvl) + 1;
        return copyF32(c, c._gip_grid(h, m, p, what), side * side * 3);
      };
      const model = {
        name: c.UTF8ToString(c._gip_model_name(h, m)),
        normalization: copyF64(c, c._gip_model_normalization(h, m), 16),
        numPatches: patches, level, normalLevel, holeMaskLevel: holeLevel,
        detailLevel: c._gip_model_field(h, m, 4), geometryPasses: c._gip_model_field(h, m, 5),
        geometry: [], normals: [], holeMask: [],
      };
      for (let p = 0; p < patches; ++p) {
        model.geometry.push(grid(p, 0, level));
        if (normalLevel >= 0) model.normals.push(grid(p, 1, normalLevel));
        if (holeLevel >= 0) model.holeMask.push(copyU8(c, c._gip_hole_mask(h, m, p), 1 << (2 * holeLevel)));
      }
      models.push(model);
    }
    return {
      status, message: statusMessage(c, status), bytesUsed: c._gip_bytes_used(h),
      chunksDecoded: c._gip_chunks_decoded(h), models,
    };
  }

  /// Scene models, as the desktop viewer draws them (morph::decode_scene): complete chunks only, positions in
  /// the normalized frame (centred, largest extent 1), `bands` wavelet bands per patch for the
  /// wavelet-schedule morph, models 1.. aligned to model 0 (`align`, default true). Per model: { name, level,
  /// numPatches, bands, positions (Float32Array [(patch·bands+band)·size²+j·size+i]·3+c), normalLevel (−1
  /// none), normals (Float32Array [patch·nsize²+…]·3), holeLevel (−1 none), holes (Uint8Array
  /// [patch·4^L+j·2^L+i]), detailLevel }.
  scene(options = {}) {
    this.check_();
    const c = this.core_, h = this.handle_;
    const status = kStatus[c._gip_decode_scene(h, options.bands ?? 1, options.align === false ? 0 : 1)];
    const models = [];
    for (let m = 0, n = c._gip_scene_count(h); m < n; ++m) {
      const f = (i) => c._gip_scene_field(h, m, i);
      models.push({
        name: c.UTF8ToString(c._gip_scene_name(h, m)), level: f(0), numPatches: f(1), bands: f(2),
        normalLevel: f(3), holeLevel: f(4), detailLevel: f(5),
        positions: copyF32(c, c._gip_scene_data(h, m, 0), f(6)),
        normals: copyF32(c, c._gip_scene_data(h, m, 1), f(7)),
        holes: copyU8(c, c._gip_scene_data(h, m, 2), f(8)),
      });
    }
    return { status, message: statusMessage(c, status), bytesUsed: c._gip_scene_bytes_used(h), models };
  }

  dispose() {
    if (this.handle_) this.core_._gip_destroy(this.handle_);
    this.handle_ = 0;
  }
}

export class GeomipError extends Error {
  constructor(status, message) {
    super(`geomip: ${message}`);
    this.status = status;
  }
}

function statusMessage(core, status) {
  return core.UTF8ToString(core._gip_status_message(kStatus.indexOf(status)));
}
function copyF32(core, ptr, n) {
  return ptr && n > 0 ? new Float32Array(core.HEAPU8.buffer, ptr, n).slice() : new Float32Array(0);
}
function copyF64(core, ptr, n) {
  return ptr ? new Float64Array(core.HEAPU8.buffer, ptr, n).slice() : new Float64Array(0);
}
function copyU8(core, ptr, n) {
  return ptr && n > 0 ? core.HEAPU8.slice(ptr, ptr + n) : new Uint8Array(0);
}
