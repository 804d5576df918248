// glb.js - reads the lit mesh that `radiosity solve -o X.glb` writes (binary glTF 2.0: one
// indexed triangle primitive with POSITION, NORMAL, COLOR_0, _RADIANCE and, when present,
// _ILLUMINANCE, each a float VEC3). Not a general glTF loader: anything else is refused
// with a message saying what is missing.

const GLB_MAGIC = 0x46546c67; // "glTF"
const CHUNK_JSON = 0x4e4f534a;
const CHUNK_BIN = 0x004e4942;
const FLOAT = 5126;
const UNSIGNED_INT = 5125;

// The typed array an accessor reads (a view into `bin`, no copy when aligned).
function accessorArray(gltf, bin, index, componentType, type) {
  const accessor = gltf.accessors && gltf.accessors[index];
  if (!accessor) throw new Error(`accessor ${index} is missing`);
  if (accessor.componentType !== componentType || accessor.type !== type)
    throw new Error(`accessor ${index} is not ${type} of component ${componentType}`);
  const view = gltf.bufferViews && gltf.bufferViews[accessor.bufferView];
  if (!view) throw new Error(`buffer view ${accessor.bufferView} is missing`);
  const components = type === 'VEC3' ? 3 : 1;
  const count = accessor.count * components;
  const offset = (view.byteOffset || 0) + (accessor.byteOffset || 0);
  if (offset + count * 4 > bin.byteLength || offset % 4 !== 0)
    throw new Error(`accessor ${index} lies outside the binary chunk`);
  const Type = componentType === FLOAT ? Float32Array : Uint32Array;
  return new Type(bin.buffer, bin.byteOffset + offset, count);
}

// Parses `bytes` (a Uint8Array holding a .glb). Returns the arrays and the asset's extras.
export function parseLitMesh(bytes) {
  if (bytes.byteLength < 20) throw new Error('the lit mesh is shorter than a .glb header');
  const data = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (data.getUint32(0, true) !== GLB_MAGIC) throw new Error('the lit mesh is not a .glb');
  const jsonLength = data.getUint32(12, true);
  if (data.getUint32(16, true) !== CHUNK_JSON || 20 + jsonLength + 8 > bytes.byteLength)
    throw new Error('the .glb has no JSON chunk');
  const gltf = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  const binStart = 20 + jsonLength;
  const binLength = data.getUint32(binStart, true);
  if (data.getUint32(binStart + 4, true) !== CHUNK_BIN || binStart + 8 + binLength > bytes.byteLength)
    throw new Error('the .glb has no binary chunk');
  const bin = bytes.subarray(binStart + 8, binStart + 8 + binLength);
  const primitive = gltf.meshes && gltf.meshes[0] && gltf.meshes[0].primitives[0];
  if (!primitive || !primitive.attributes) throw new Error('the .glb has no mesh');
  const attributes = primitive.attributes;
  for (const name of ['POSITION', '_RADIANCE'])
    if (attributes[name] === undefined)
      throw new Error(`the .glb has no ${name}: not a lit mesh of radiosity solve`);
  if (primitive.indices === undefined) throw new Error('the .glb has no triangle indices');
  const vec3 = (name) =>
    attributes[name] === undefined ? null : accessorArray(gltf, bin, attributes[name], FLOAT, 'VEC3');
  const mesh = {
    position: vec3('POSITION'),
    normal: vec3('NORMAL'),
    radiance: vec3('_RADIANCE'),
    illuminance: vec3('_ILLUMINANCE'),
    index: accessorArray(gltf, bin, primitive.indices, UNSIGNED_INT, 'SCALAR'),
    extras: (gltf.asset && gltf.asset.extras) || {},
  };
  const vertices = mesh.position.length / 3;
  for (const name of ['normal', 'radiance', 'illuminance'])
    if (mesh[name] && mesh[name].length !== mesh.position.length)
      throw new Error(`the .glb's ${name} has another vertex count than its positions`);
  for (let k = 0; k < mesh.index.length; k++)
    if (mesh.index[k] >= vertices) throw new Error(`the .glb's triangle index ${k} is out of range`);
  return mesh;
}
