// The editor's wire format (serve/wire.rs), the answer of POST /api/model: a little-endian
// u32 header length, the JSON header (padded to 4 bytes), then the buffers the header's
// { offset, count } slices point into (little-endian f32 and u32).

// The header and the buffers of an answer.
export function decode(bytes) {
  const n = new DataView(bytes).getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(bytes, 4, n)));
  return { header, data: bytes.slice(4 + n) };
}

// FNV-1a (32 bits, hex) of the buffers as received: what the tests compare, so that a
// change is seen in the bytes that were drawn, not in a label the server sends with them.
export function bytesHash(data) {
  let h = 0x811c9dc5;
  for (const b of new Uint8Array(data)) h = Math.imul(h ^ b, 0x01000193) >>> 0;
  return h.toString(16).padStart(8, "0");
}

// A slice of f32 values (positions, normals, curves, fields).
export const f32 = (data, slice) => new Float32Array(data, slice.offset, slice.count);

// A slice of u32 values (triangle and line indices).
export const u32 = (data, slice) => new Uint32Array(data, slice.offset, slice.count);
