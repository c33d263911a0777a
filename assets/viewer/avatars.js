// bmlr view: characters drawn as their avatars. Each avatar is a GLB in the page data, loaded
// with three.js's GLTFLoader from the page's own text (so the page works opened from disk);
// its character's mannequin is hidden behind it (M shows it again). A recorded run's avatars
// carry their motion and face as an animation (made as `bmlr run --gltf` makes it), set to the
// cursor's time. A live page's avatars come without motion, with their wiring (the character
// each shows, its moving nodes, the travelling node, its morph nodes); each frame from the
// WebSocket brings their nodes' rotations and morph weights, interpolated here between frames.
'use strict';

/** A module URL of three.js's GLTFLoader working from the page's own text. */
function bmlrGltfLoader(viewer) {
  const text = (id) => document.getElementById(id).textContent;
  const module = (s) => URL.createObjectURL(new Blob([s], { type: 'text/javascript' }));
  const three = (s) => s.replace(/from 'three'/g, `from '${viewer.threeURL}'`);
  const utils = module(three(text('three-geometry-utils')));
  // textures decoded from <img> elements, not ImageBitmaps: an ImageBitmap decodes off the
  // page's thread, where a headless browser's virtual time does not wait for it, so a picture
  // taken under a virtual-time budget now and then showed the page before the avatar was in it
  return module(
    three(text('three-gltf'))
      .replace("'../utils/BufferGeometryUtils.js'", `'${utils}'`)
      .replace("typeof createImageBitmap === 'undefined'", 'true'),
  );
}

/** Loads the page data's avatars into `viewer`'s scene; `fail` reports an error on the page. */
function bmlrLoadAvatars(viewer, fail) {
  const THREE = viewer.THREE;
  const avatars = viewer.data.avatars || [];
  const wiring = viewer.data.liveAvatars || [];
  if (viewer.data.crowdAvatar && viewer.crowd) bmlrLoadCrowdPeople(viewer, fail);
  if (!avatars.length) return;
  const loader = bmlrGltfLoader(viewer);
  viewer.avatarsLoading = avatars.length;
  const done = () => {
    viewer.avatarsLoading--;
    viewer.draw();
  };
  // live avatars of characters that have not appeared yet wait for their figure
  const waiting = new Map();
  const attach = (k, avatar) => {
    const f = viewer.figures[k];
    f.avatar = avatar;
    f.nodes[0].visible = false;
  };
  viewer.attachAvatar = (k) => {
    const id = viewer.clip.characters[k];
    if (waiting.has(id)) attach(k, waiting.get(id));
    waiting.delete(id);
  };
  const loaded = (gltf, k) => {
    gltf.scene.traverse((o) => { if (o.isSkinnedMesh) o.frustumCulled = false; });
    viewer.scene.add(gltf.scene);
    if (k === 0) {
      // the close look at the face at the first avatar's eyes (about 11 cm under the top of
      // its head), not the mannequin's
      const top = new THREE.Box3().setFromObject(gltf.scene).max.y;
      if (Number.isFinite(top) && top > 0.5) {
        const close = viewer.view.height === viewer.close.height;
        viewer.close.height = top - 0.11;
        if (close) viewer.view.height = viewer.close.height;
      }
    }
    if (!viewer.data.live) {
      const mixer = new THREE.AnimationMixer(gltf.scene);
      if (gltf.animations.length) {
        const action = mixer.clipAction(gltf.animations[0]);
        action.setLoop(THREE.LoopOnce);
        action.clampWhenFinished = true;
        action.play();
      }
      attach(k, { root: gltf.scene, mixer });
      return;
    }
    const w = wiring[k];
    const byIndex = [];
    gltf.scene.traverse((o) => {
      const a = gltf.parser.associations.get(o);
      if (a && a.nodes !== undefined) byIndex[a.nodes] = o;
    });
    const meshes = (o) => (!o ? [] : o.isMesh ? [o] : o.children.filter((c) => c.isMesh));
    const avatar = {
      root: gltf.scene,
      live: {
        moving: w.moving.map((i) => byIndex[i]),
        hips: byIndex[w.hips],
        morphs: w.morphs.map(([node, count]) => ({ meshes: meshes(byIndex[node]), count })),
      },
    };
    const at = viewer.clip.characters.indexOf(w.id);
    if (at >= 0) attach(at, avatar);
    else waiting.set(w.id, avatar);
  };
  import(loader).then(
    ({ GLTFLoader }) => avatars.forEach((glb, k) => {
      const bytes = Uint8Array.from(atob(glb), (c) => c.charCodeAt(0));
      new GLTFLoader().parse(bytes.buffer, '', (gltf) => {
        loaded(gltf, k);
        done();
      }, (e) => { fail('an avatar did not load: ' + e); done(); });
    }),
    (e) => { fail("three.js's GLTFLoader did not load: " + e); viewer.avatarsLoading = 0; },
  );
}

/** Sets live `avatar`'s nodes and morph weights from character `id`'s data in `clip` at `t`. */
function bmlrDriveLive(THREE, avatar, clip, t, id) {
  if (!clip.times.length) return;
  const i = clip.index(t);
  const j = Math.min(i + 1, clip.times.length - 1);
  const a = (clip.avatars[i] || {})[id];
  if (!a) return;
  const b = (clip.avatars[j] || {})[id] || a;
  const span = clip.times[j] - clip.times[i];
  const f = span > 0 ? Math.min(Math.max((t - clip.times[i]) / span, 0), 1) : 0;
  const live = avatar.live;
  const q = bmlrDriveLive.scratch || (bmlrDriveLive.scratch = new THREE.Quaternion());
  live.moving.forEach((node, m) => {
    if (!node) return;
    node.quaternion.fromArray(a.r, 4 * m).slerp(q.fromArray(b.r, 4 * m), f);
  });
  const h = 4 * live.moving.length;
  if (live.hips) {
    live.hips.position.set(
      a.r[h] + (b.r[h] - a.r[h]) * f,
      a.r[h + 1] + (b.r[h + 1] - a.r[h + 1]) * f,
      a.r[h + 2] + (b.r[h + 2] - a.r[h + 2]) * f,
    );
  }
  let o = 0;
  for (const m of live.morphs) {
    for (let c = 0; c < m.count; c++) {
      const v = a.w[o + c] + (b.w[o + c] - a.w[o + c]) * f;
      for (const mesh of m.meshes) {
        if (mesh.morphTargetInfluences) mesh.morphTargetInfluences[c] = v;
      }
    }
    o += m.count;
  }
}

/** A crowd drawn as people: the default avatar (the page's `crowdAvatar`, whose bones are the
 *  realizer's joints by name) copied once per character, every copy a skinned mesh sharing the
 *  one geometry and material with a skeleton of its own; the crowd's mannequin boxes hide. */
function bmlrLoadCrowdPeople(viewer, fail) {
  const crowd = viewer.crowd;
  viewer.avatarsLoading++;
  const bytes = Uint8Array.from(atob(viewer.data.crowdAvatar), (c) => c.charCodeAt(0));
  const finish = () => {
    viewer.avatarsLoading--;
    viewer.draw();
  };
  import(bmlrGltfLoader(viewer)).then(
    ({ GLTFLoader }) => new GLTFLoader().parse(bytes.buffer, '', (gltf) => {
      const people = [];
      for (let k = 0; k < crowd.count; k++) {
        const copy = gltf.scene.clone(true);
        const byName = new Map();
        copy.traverse((o) => { if (o.name) byName.set(o.name, o); });
        // a clone's skinned meshes still point at the original's bones: bind them to the copy's
        copy.traverse((o) => {
          if (!o.isSkinnedMesh) return;
          const bones = o.skeleton.bones.map((b) => byName.get(b.name) || b);
          o.bind(new viewer.THREE.Skeleton(bones, o.skeleton.boneInverses), o.bindMatrix);
          o.frustumCulled = false;
        });
        viewer.scene.add(copy);
        people.push(crowd.joints.map((j) => byName.get(j.name) || null));
      }
      crowd.people = people;
      for (const mesh of crowd.meshes) mesh.visible = false;
      finish();
    }, (e) => { fail('the crowd\'s avatar did not load: ' + e); finish(); }),
    (e) => { fail("three.js's GLTFLoader did not load: " + e); finish(); },
  );
}
