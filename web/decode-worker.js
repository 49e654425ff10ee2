// The viewer's decoding thread (a module worker): holds its own copy of the bytes received and decodes scene
// models on request, so that the page's main thread never waits on a decode (web/viewer.js). Messages in:
// { type: 'push', bytes } and { type: 'scene', bands }; out: { type: 'scene', scene, size, ms } (the typed
// arrays transferred), or { type: 'error', message }.
import { createDecoder } from './geomip.js';

const ready = createDecoder();
self.onmessage = async ({ data }) => {
  try {
    const decoder = await ready;
    if (data.type === 'push') {
      decoder.push(data.bytes);
    } else if (data.type === 'scene') {
      const t0 = performance.now();
      const scene = decoder.scene({ bands: data.bands });
      const ms = performance.now() - t0;
      const transfer = scene.models.flatMap((m) => [m.positions.buffer, m.normals.buffer, m.holes.buffer]);
      self.postMessage({ type: 'scene', scene, size: decoder.size, ms }, transfer);
    }
  } catch (e) {
    self.postMessage({ type: 'error', message: e.message });
  }
};
