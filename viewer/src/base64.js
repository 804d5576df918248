// base64.js - decodes the base64 text the page embeds (the lit mesh, the surface of each
// triangle) into bytes, fast enough for tens of megabytes. Not a general codec: no
// line breaks or URL-safe alphabet.

const ALPHABET = 'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/';
const VALUE = new Uint8Array(256).fill(255);
for (let k = 0; k < ALPHABET.length; k++) VALUE[ALPHABET.charCodeAt(k)] = k;

export function decodeBase64(text) {
  text = text.trim();
  let length = text.length;
  if (length % 4 !== 0) throw new Error('embedded data: base64 length is not a multiple of 4');
  let padding = 0;
  if (length > 0 && text[length - 1] === '=') padding++;
  if (length > 1 && text[length - 2] === '=') padding++;
  const out = new Uint8Array((length / 4) * 3 - padding);
  let o = 0;
  for (let i = 0; i < length; i += 4) {
    const a = VALUE[text.charCodeAt(i)], b = VALUE[text.charCodeAt(i + 1)];
    const c = text[i + 2] === '=' ? 0 : VALUE[text.charCodeAt(i + 2)];
    const d = text[i + 3] === '=' ? 0 : VALUE[text.charCodeAt(i + 3)];
    if ((a | b | c | d) & 0xc0) throw new Error('embedded data: not base64');
    const triple = (a << 18) | (b << 12) | (c << 6) | d;
    if (o < out.length) out[o++] = triple >> 16;
    if (o < out.length) out[o++] = (triple >> 8) & 255;
    if (o < out.length) out[o++] = triple & 255;
  }
  return out;
}
