// Loads binary glTF files with three.js's own GLTFLoader (npm three, the release the viewer
// vendors), as a web page would: each must parse, hold a skinned mesh whose skeleton has bones,
// and, if it is an avatar with a face, the 52 ARKit morph targets and an animation that keys
// their weights (with --any-face: any number of morph targets, their weights keyed). Exits 1 if
// any file fails.
// Usage: node .ci/check_gltf_three.mjs [--any-face] FILE.glb...  (three installed where Node finds it)
import fs from 'fs';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

let failed = 0;
const anyFace = process.argv.includes('--any-face');
for (const path of process.argv.slice(2).filter((a) => a !== '--any-face')) {
  const bytes = fs.readFileSync(path);
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  try {
    const gltf = await new Promise((ok, fail) => new GLTFLoader().parse(buffer, '', ok, fail));
    let skinned = 0, bones = 0, morphs = 0;
    gltf.scene.traverse((o) => {
      if (o.isSkinnedMesh) {
        skinned++;
        bones = Math.max(bones, o.skeleton.bones.length);
        morphs = Math.max(morphs, Object.keys(o.morphTargetDictionary || {}).length);
      }
    });
    const clip = gltf.animations[0];
    const tracks = clip ? clip.tracks.length : 0;
    const weights = clip ? clip.tracks.filter((t) => t.name.endsWith('.morphTargetInfluences')).length : 0;
    console.log(`${path}: ${skinned} skinned meshes, ${bones} bones, ${morphs} morph targets, ${tracks} tracks (${weights} of weights), ${clip ? clip.duration.toFixed(3) : 0} s`);
    if (!skinned || !bones || (morphs && !anyFace && morphs !== 52) || (morphs && !weights)) {
      console.log('  not an animated skinned avatar as expected');
      failed++;
    }
  } catch (e) {
    console.log(`${path}: GLTFLoader failed: ${e}`);
    failed++;
  }
}
process.exit(failed ? 1 : 0);
