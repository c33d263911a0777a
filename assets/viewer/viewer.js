// bmlr view: the page that shows a realized BML run. It reads the run from the page itself
// (the JSON in #bmlr-data: the frames file's header and frames, the mannequin's boxes, the
// feedback with the time each message was sent, the timeline picture and the world's points)
// or, live, from a WebSocket that sends the same frames and feedback as they happen. It draws
// the mannequin with three.js (loaded from the page's own text, so that the page works opened
// from disk) with its face (brows, lids and mouth moved by the frames' blendshapes), the world's
// points, a cursor over the timeline and the feedback up to the cursor, with play / pause /
// scrub / speed, and the run's sound (if it has any) played in step with the cursor. Characters
// with an avatar in the page data are drawn as that avatar (avatars.js: GLTFLoader, an animation
// per character, or live the avatars' node rotations and morph weights with each frame; M
// toggles the mannequin). A crowd (more than 16 characters) comes packed and is drawn as one
// (crowd.js: instanced mannequins, no faces). It opens paused at #t=SECONDS and sets the title to
// "bmlr view: ready" once the first frame is drawn with every avatar loaded.
'use strict';

(function () {
  const data = JSON.parse(document.getElementById('bmlr-data').textContent);
  const source = document.getElementById('three-source').textContent;
  const url = URL.createObjectURL(new Blob([source], { type: 'text/javascript' }));
  import(url).then(
    (THREE) => new Viewer(THREE, data, url).start(),
    (e) => fail('three.js did not load: ' + e),
  );

  function fail(message) {
    const box = document.getElementById('error');
    box.textContent = message;
    box.style.display = 'block';
    console.error(message);
  }

  /** Frames a live page keeps (ten minutes at 30 a second); older ones are let go. */
  const LIVE_FRAMES = 18000;
  /** A world point's name: its size (m) and how far above its ball it floats. */
  const LABEL_WIDTH = 0.32;
  const LABEL_HEIGHT = 0.08;
  const LABEL_ABOVE = 0.08;
  /** The box round a person that names keep out of: radius about the root and height (m). */
  const BODY_RADIUS = 0.25;
  const BODY_HEIGHT = 1.85;

  /** The frames of a run: times, and per frame each character's root and joint rotations. */
  class Clip {
    constructor(header) {
      this.joints = header.skeleton.joints;
      this.characters = header.characters.slice();
      this.times = [];
      // per frame, per character: root x y z, rotation x y z w, then x y z w per joint
      this.poses = [];
      this.clamped = [];
      // per frame, per character: the blendshapes that are not 0
      this.morphs = [];
      // live, per frame: each avatar's node rotations and morph weights (by character id)
      this.avatars = [];
      // the rest pose, for a character in the frames before it first appears
      this.rest = new Float32Array(7 + 4 * this.joints.length);
      this.rest.set(this.joints[0].offset, 0);
      for (let q = 6; q < this.rest.length; q += 4) this.rest[q] = 1;
      this.added = () => {};
      this.a = new Float32Array(this.rest.length);
      this.b = new Float32Array(this.rest.length);
    }

    /** A crowd's packed frames (crowd.js) instead of frame lines. */
    unpack(packed) {
      this.packed = new BmlrPackedFrames(packed, this.joints);
      this.characters = packed.characters.slice();
      this.times = packed.times.slice();
    }

    /** Frame i of character k (`out` is scratch space for packed frames). */
    frameOf(i, k, out) {
      if (this.packed) return this.packed.pose(i, k, out);
      return this.poses[i][k] || this.rest;
    }

    get duration() {
      return this.times.length ? this.times[this.times.length - 1] : 0;
    }

    /** The first frame's time (a live page starts when the watcher connects). */
    get start() {
      return this.times.length ? this.times[0] : 0;
    }

    /** Adds a frame line of the frames file (frames arrive in time order), live with its
     * avatars' data. */
    push(frame, avatars) {
      for (const id of Object.keys(frame.characters)) {
        if (!this.characters.includes(id)) {
          this.characters.push(id);
          this.added(this.characters.length - 1);
        }
      }
      const poses = this.characters.map((id) => {
        const c = frame.characters[id];
        if (!c) return this.rest;
        const pose = new Float32Array(7 + 4 * this.joints.length);
        pose.set(c.root, 0);
        pose.set(c.rotation, 3);
        this.joints.forEach((j, k) => pose.set(c.joints[j.name] || [0, 0, 0, 1], 7 + 4 * k));
        return pose;
      });
      this.times.push(frame.time);
      this.poses.push(poses);
      this.clamped.push(this.characters.map((id) => (frame.characters[id] || {}).clamped || []));
      this.morphs.push(this.characters.map((id) => (frame.characters[id] || {}).morphs || {}));
      this.avatars.push(avatars || null);
      if (this.times.length > LIVE_FRAMES) {
        const drop = LIVE_FRAMES / 10;
        this.times.splice(0, drop);
        this.poses.splice(0, drop);
        this.clamped.splice(0, drop);
        this.morphs.splice(0, drop);
        this.avatars.splice(0, drop);
      }
    }

    /** The index of the last frame at or before `t` (0 before the first). */
    index(t) {
      let lo = 0;
      let hi = this.times.length - 1;
      while (lo < hi) {
        const mid = (lo + hi + 1) >> 1;
        if (this.times[mid] <= t) lo = mid;
        else hi = mid - 1;
      }
      return lo;
    }

    /** Character `k`'s blendshape `name` at time `t`, interpolated between frames. */
    morph(t, k, name) {
      if (this.packed) return 0;
      const i = this.index(t);
      const j = Math.min(i + 1, this.times.length - 1);
      const span = this.times[j] - this.times[i];
      const f = span > 0 ? Math.min(Math.max((t - this.times[i]) / span, 0), 1) : 0;
      const a = (this.morphs[i][k] || {})[name] || 0;
      const b = (this.morphs[j][k] || {})[name] || 0;
      return a + (b - a) * f;
    }

    /** Character `k`'s pose at time `t`, interpolated between frames, into `out`. */
    sample(THREE, t, k, out) {
      const i = this.index(t);
      const a = this.frameOf(i, k, this.a);
      const j = Math.min(i + 1, this.times.length - 1);
      const span = this.times[j] - this.times[i];
      const f = span > 0 ? Math.min(Math.max((t - this.times[i]) / span, 0), 1) : 0;
      const b = this.frameOf(j, k, this.b);
      for (let c = 0; c < 3; c++) out[c] = a[c] + (b[c] - a[c]) * f;
      for (let q = 3; q < out.length; q += 4) THREE.Quaternion.slerpFlat(out, q, a, q, b, q, f);
      return out;
    }
  }

  /** Where world point keys put a point at time `t` (linear, resting before and after). */
  function along(keys, t) {
    if (t <= keys[0][0]) return keys[0][1];
    for (let i = 1; i < keys.length; i++) {
      if (t <= keys[i][0]) {
        const [t0, a] = keys[i - 1];
        const [t1, b] = keys[i];
        const f = t1 > t0 ? (t - t0) / (t1 - t0) : 1;
        return a.map((v, c) => v + (b[c] - v) * f);
      }
    }
    return keys[keys.length - 1][1];
  }

  /** The convex hull of points [x, z] (monotone chain), counter-clockwise. */
  function convexHull(points) {
    const p = points.slice().sort((a, b) => a[0] - b[0] || a[1] - b[1]);
    if (p.length < 3) return p;
    const cross = (o, a, b) => (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    const half = (list) => {
      const out = [];
      for (const q of list) {
        while (out.length >= 2 && cross(out[out.length - 2], out[out.length - 1], q) <= 0) out.pop();
        out.push(q);
      }
      out.pop();
      return out;
    };
    return half(p).concat(half(p.slice().reverse()));
  }

  function fmt(t) {
    return t.toFixed(3) + ' s';
  }

  class Viewer {
    constructor(THREE, data, threeURL) {
      this.THREE = THREE;
      this.threeURL = threeURL;
      // characters' avatars still loading (the page is not ready before they are drawn)
      this.avatarsLoading = 0;
      this.data = data;
      this.clip = new Clip(data.header);
      if (data.packed) this.clip.unpack(data.packed);
      data.frames.forEach((f) => this.clip.push(f));
      this.feedback = [];
      this.shown = 0;
      this.t = 0;
      this.playing = false;
      this.following = !!data.live;
      this.speed = 1;
      this.drawn = false;
      this.last = null;
      this.sound = data.audio ? new Audio(data.audio) : null;
      // the centre of mass and the support polygon: #com in the address, or the C key
      this.showBalance = /(?:^#|&)com(?:&|$)/.test(location.hash);
    }

    start() {
      this.scene3d();
      if (this.clip.packed) {
        const { joints, characters } = this.clip;
        this.crowd = new BmlrCrowd(this.THREE, this.scene, joints, this.data.segments, this.materials, characters.length);
        this.crowdPose = new Float32Array(this.clip.rest.length);
      }
      this.figures = this.crowd ? [] : this.clip.characters.map((id, k) => this.figure(k));
      this.fitFloor();
      this.clip.added = (k) => {
        this.figures.push(this.figure(k));
        if (this.attachAvatar) this.attachAvatar(k);
      };
      this.worldPoints();
      this.loadAvatars();
      this.controls();
      this.orbit();
      this.setTimeline(this.data.timeline);
      this.data.feedback.forEach((m) => this.addFeedback(m));
      this.refreshFeedbackEmpty();
      const caption = this.data.title + (this.data.live ? ' (live)' : '') + (this.sound ? ' ♪' : '');
      document.getElementById('what').textContent = caption;
      this.seek(this.hashTime());
      window.addEventListener('hashchange', () => {
        this.pause();
        this.seek(this.hashTime());
      });
      if (this.data.live) this.connect();
      requestAnimationFrame((now) => this.frame(now));
    }

    /** The time of the page address (#t=SECONDS), else 0. */
    hashTime() {
      const m = /(?:^#|&)t=([0-9]*\.?[0-9]+)/.exec(location.hash);
      return m ? parseFloat(m[1]) : 0;
    }

    scene3d() {
      const THREE = this.THREE;
      this.canvas = document.getElementById('scene');
      this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: true });
      this.renderer.setPixelRatio(window.devicePixelRatio || 1);
      this.scene = new THREE.Scene();
      this.scene.background = new THREE.Color(0xdde3ea);
      this.camera = new THREE.PerspectiveCamera(32, 1, 0.05, 100);
      this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 2.2));
      const sun = new THREE.DirectionalLight(0xffffff, 2.0);
      sun.position.set(2, 4, 3);
      this.scene.add(sun);
      const floor = (this.floor = new THREE.Mesh(
        new THREE.CircleGeometry(4, 48),
        new THREE.MeshLambertMaterial({ color: 0xc9ced6 }),
      ));
      floor.rotation.x = -Math.PI / 2;
      this.scene.add(floor);
      const grid = (this.grid = new THREE.GridHelper(8, 16, 0xaab1bc, 0xb8bec8));
      grid.position.y = 0.001;
      this.scene.add(grid);
      this.materials = [
        new THREE.MeshStandardMaterial({ color: 0x3f5473, roughness: 0.8 }),
        new THREE.MeshStandardMaterial({ color: 0xdcab8c, roughness: 0.6 }),
      ];
      this.resize();
      window.addEventListener('resize', () => this.resize());
    }

    /** A floor under everywhere the characters go (4 m round the middle, or more). */
    fitFloor() {
      const s = this.stage(false);
      const scale = Math.max(1, (s.spread + 2) / 4);
      for (const m of [this.floor, this.grid]) {
        m.position.x = s.x;
        m.position.z = s.z;
      }
      this.floor.scale.set(scale, scale, 1);
      this.grid.scale.set(scale, 1, scale);
    }

    resize() {
      const w = this.canvas.clientWidth || 1;
      const h = this.canvas.clientHeight || 1;
      this.renderer.setSize(w, h, false);
      this.camera.aspect = w / h;
      this.camera.updateProjectionMatrix();
    }

    /** Character `k`'s mannequin: a group per joint, the boxes on the joints they follow. */
    figure(k) {
      const THREE = this.THREE;
      const joints = this.clip.joints;
      const index = new Map(joints.map((j, i) => [j.name, i]));
      const nodes = joints.map((j) => {
        const g = new THREE.Group();
        g.position.fromArray(j.offset);
        return g;
      });
      const rest = [];
      joints.forEach((j, i) => {
        const p = new THREE.Vector3().fromArray(j.offset);
        if (j.parent !== null) {
          const parent = index.get(j.parent);
          nodes[parent].add(nodes[i]);
          p.add(rest[parent]);
        } else {
          this.scene.add(nodes[i]);
        }
        rest.push(p);
      });
      const up = new THREE.Vector3(0, 1, 0);
      for (const s of this.data.segments) {
        const a = new THREE.Vector3().fromArray(s.from);
        const b = new THREE.Vector3().fromArray(s.to);
        const length = Math.max(a.distanceTo(b), 0.01);
        const box = new THREE.Mesh(
          new THREE.BoxGeometry(s.width, length, s.width),
          this.materials[s.skin ? 1 : 0],
        );
        box.position.copy(a).add(b).multiplyScalar(0.5).sub(rest[s.joint]);
        if (length > 0.01) box.quaternion.setFromUnitVectors(up, b.clone().sub(a).normalize());
        nodes[s.joint].add(box);
      }
      const face = this.face(index, rest, nodes);
      const balance = this.balanceMarks(index);
      return { nodes, face, balance, pose: new Float32Array(7 + 4 * joints.length), k };
    }

    /** Each character's avatar, drawn instead of its mannequin (avatars.js). */
    loadAvatars() {
      bmlrLoadAvatars(this, fail);
    }

    /**
     * The centre of mass (a red ball with a line down to the floor) and the support polygon (the
     * hull of the soles' corners on the floor), from the physical humanoid's parts in the page
     * data; shown with #com in the address or the C key.
     */
    balanceMarks(index) {
      const THREE = this.THREE;
      const parts = (this.data.parts || []).filter((p) => index.has(p.joint));
      if (!parts.length) return null;
      const red = new THREE.MeshBasicMaterial({ color: 0xd03030, depthTest: false });
      const ball = new THREE.Mesh(new THREE.SphereGeometry(0.03, 16, 12), red);
      ball.renderOrder = 2;
      const line = (color) => {
        const l = new THREE.Line(
          new THREE.BufferGeometry(),
          new THREE.LineBasicMaterial({ color, depthTest: false }),
        );
        l.renderOrder = 2;
        return l;
      };
      const drop = line(0xd03030);
      const polygon = line(0x2060c0);
      const group = new THREE.Group();
      group.add(ball, drop, polygon);
      group.visible = this.showBalance;
      this.scene.add(group);
      return { parts: parts.map((p) => ({ ...p, j: index.get(p.joint) })), ball, drop, polygon, group };
    }

    /** Moves figure `f`'s centre of mass and support polygon to its pose. */
    balance(f) {
      const b = f.balance;
      if (!b) return;
      b.group.visible = this.showBalance;
      if (!this.showBalance) return;
      const THREE = this.THREE;
      f.nodes[0].updateMatrixWorld(true);
      const c = new THREE.Vector3();
      const corners = [];
      let mass = 0;
      for (const p of b.parts) {
        const m = f.nodes[p.j].matrixWorld;
        c.addScaledVector(new THREE.Vector3().fromArray(p.com).applyMatrix4(m), p.mass);
        mass += p.mass;
        for (const s of p.sole || []) {
          const q = new THREE.Vector3().fromArray(s).applyMatrix4(m);
          if (q.y < 0.02) corners.push([q.x, q.z]);
        }
      }
      c.multiplyScalar(1 / mass);
      b.ball.position.copy(c);
      b.drop.geometry.setFromPoints([c, new THREE.Vector3(c.x, 0.002, c.z)]);
      const hull = convexHull(corners).map(([x, z]) => new THREE.Vector3(x, 0.003, z));
      if (hull.length) hull.push(hull[0]);
      b.polygon.geometry.setFromPoints(hull);
    }

    /** Brows, lids and a mouth on the front of the head box, moved by the blendshapes. */
    face(index, rest, nodes) {
      const THREE = this.THREE;
      const head = index.get('skullbase');
      if (head === undefined) return null;
      const at = (name) => rest[index.get(name)].clone().sub(rest[head]);
      const front = 0.118;
      const dark = new THREE.MeshStandardMaterial({ color: 0x3b2a22, roughness: 0.9 });
      const lid = new THREE.MeshStandardMaterial({ color: 0xc9977a, roughness: 0.7 });
      const lips = new THREE.MeshStandardMaterial({ color: 0x6e2a2a, roughness: 0.8 });
      const part = (w, h, d, material, x, y, z) => {
        const g = new THREE.Group();
        g.position.set(x, y, z);
        const m = new THREE.Mesh(new THREE.BoxGeometry(w, h, d), material);
        g.add(m);
        nodes[head].add(g);
        return { g, m, y };
      };
      const sides = [['Left', 'l_eyeball_joint'], ['Right', 'r_eyeball_joint']].map(([side, joint]) => {
        const eye = at(joint);
        const brow = part(0.036, 0.007, 0.008, dark, eye.x, eye.y + 0.026, front);
        // the lid hangs from the top of the eye: its box is moved down by half its height
        const cover = part(0.03, 0.026, 0.006, lid, eye.x, eye.y + 0.013, front + 0.004);
        cover.m.position.y = -0.013;
        return { side, brow, cover };
      });
      const mouth = part(0.045, 0.006, 0.006, lips, 0, 0.016, front);
      return { sides, mouth };
    }

    /** Moves figure `f`'s face to the blendshapes at time `t`. */
    expression(f, t) {
      if (!f.face || !this.clip.times.length) return;
      const m = (name) => this.clip.morph(t, f.k, name);
      for (const { side, brow, cover } of f.face.sides) {
        const up = 0.5 * m('browInnerUp') + m('browOuterUp' + side);
        brow.g.position.y = brow.y + 0.012 * up - 0.008 * m('browDown' + side);
        // a lowered brow's inner end goes down, a raised inner brow's up (the left brow is on
        // the +x side: turning it about +z lowers its inner end)
        brow.g.rotation.z = (side === 'Left' ? 1 : -1) * (0.35 * m('browDown' + side) - 0.25 * m('browInnerUp'));
        const closed = Math.min(Math.max(m('eyeBlink' + side) - 0.4 * m('eyeWide' + side), 0), 1);
        cover.g.scale.y = Math.max(closed, 0.001);
      }
      const smile = (m('mouthSmileLeft') + m('mouthSmileRight')) / 2;
      const frown = (m('mouthFrownLeft') + m('mouthFrownRight')) / 2;
      const stretch = (m('mouthStretchLeft') + m('mouthStretchRight')) / 2;
      const round = Math.max(m('mouthPucker'), m('mouthFunnel'));
      const pressed = (m('mouthPressLeft') + m('mouthPressRight')) / 2;
      const mouth = f.face.mouth;
      mouth.g.scale.x = Math.max(1 + 0.45 * smile + 0.3 * stretch - 0.45 * round, 0.3);
      const open = m('jawOpen') + 0.4 * (m('mouthLowerDownLeft') + m('mouthLowerDownRight')) / 2;
      mouth.g.scale.y = Math.max(1 + 6 * open + 2 * round - 0.8 * pressed, 0.2);
      mouth.g.position.y = mouth.y + 0.005 * smile - 0.005 * frown - 0.012 * open;
    }

    /** Every world point as a small sphere with its name; paths as lines. */
    worldPoints() {
      const THREE = this.THREE;
      const world = this.data.world || { points: {}, paths: {} };
      this.points = [];
      const material = new THREE.MeshStandardMaterial({ color: 0xd9822b });
      for (const [name, at] of Object.entries(world.points)) {
        const ball = new THREE.Mesh(new THREE.SphereGeometry(0.035, 16, 12), material);
        ball.position.fromArray(at);
        const label = this.label(name);
        label.position.set(0, LABEL_ABOVE, 0);
        ball.add(label);
        // a thin line from the ball to its name when the name had to move aside
        const leader = new THREE.Line(
          new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]),
          new THREE.LineBasicMaterial({ color: 0xb39a80 }),
        );
        leader.visible = false;
        ball.add(leader);
        this.scene.add(ball);
        this.points.push({ ball, label, leader, keys: (world.paths || {})[name] });
      }
      // obstacles: grey blocks to their height
      const grey = new THREE.MeshStandardMaterial({ color: 0x8a8f98, transparent: true, opacity: 0.6 });
      for (const o of world.obstacles || []) {
        const h = o.height;
        let mesh = null;
        if (o.circle) {
          const [x, z, r] = o.circle;
          mesh = new THREE.Mesh(new THREE.CylinderGeometry(r, r, h, 32), grey);
          mesh.position.set(x, h / 2, z);
        } else if (o.box) {
          const [x0, z0, x1, z1] = o.box;
          mesh = new THREE.Mesh(new THREE.BoxGeometry(x1 - x0, h, z1 - z0), grey);
          mesh.position.set((x0 + x1) / 2, h / 2, (z0 + z1) / 2);
        } else if (o.segment) {
          const [x0, z0, x1, z1] = o.segment;
          mesh = new THREE.Mesh(new THREE.BoxGeometry(Math.hypot(x1 - x0, z1 - z0), h, 0.04), grey);
          mesh.position.set((x0 + x1) / 2, h / 2, (z0 + z1) / 2);
          mesh.rotation.y = -Math.atan2(z1 - z0, x1 - x0);
        }
        if (mesh) this.scene.add(mesh);
      }
      for (const keys of Object.values(world.paths || {})) {
        const line = new THREE.Line(
          new THREE.BufferGeometry().setFromPoints(keys.map((k) => new THREE.Vector3().fromArray(k[1]))),
          new THREE.LineDashedMaterial({ color: 0xd9822b, dashSize: 0.05, gapSize: 0.04 }),
        );
        line.computeLineDistances();
        this.scene.add(line);
      }
    }

    /**
     * Keeps each world point's name off the people: above its ball, unless that would cross a
     * body on the screen (a box round each character, feet to head); then at the nearest place
     * beside the people that crosses none and stays in the view, else above them all.
     */
    placeLabels() {
      const THREE = this.THREE;
      const camera = this.camera;
      camera.updateMatrixWorld();
      const scratch = this.labelScratch || (this.labelScratch = {
        v: new THREE.Vector3(), right: new THREE.Vector3(), up: new THREE.Vector3(),
      });
      const { v, right, up } = scratch;
      right.setFromMatrixColumn(camera.matrixWorld, 0);
      up.setFromMatrixColumn(camera.matrixWorld, 1);
      // the people's boxes on the screen (normalized device coordinates)
      const boxes = this.figures.map((f) => {
        const root = f.nodes[0].position;
        const box = { x0: Infinity, x1: -Infinity, y0: Infinity, y1: -Infinity };
        for (const dx of [-BODY_RADIUS, BODY_RADIUS]) {
          for (const dz of [-BODY_RADIUS, BODY_RADIUS]) {
            for (const y of [0, BODY_HEIGHT]) {
              v.set(root.x + dx, y, root.z + dz).project(camera);
              box.x0 = Math.min(box.x0, v.x); box.x1 = Math.max(box.x1, v.x);
              box.y0 = Math.min(box.y0, v.y); box.y1 = Math.max(box.y1, v.y);
            }
          }
        }
        return box;
      });
      const tan = Math.tan((camera.fov * Math.PI) / 360);
      // (what was placed, for the page's tests: the people's boxes and the names' on the screen)
      this.placed = { people: boxes, names: [] };
      for (const p of this.points) {
        const ball = p.ball.position;
        // half the label's size on the screen, at the ball's depth
        const depth = v.copy(ball).applyMatrix4(camera.matrixWorldInverse).z;
        const perNdc = Math.max(-depth, 1e-3) * tan; // world units per unit of NDC (vertical)
        const half = { x: LABEL_WIDTH / 2 / (perNdc * camera.aspect), y: LABEL_HEIGHT / 2 / perNdc };
        v.copy(ball).addScaledVector(up, LABEL_ABOVE).project(camera);
        const at = { x: v.x, y: v.y };
        const clear = (x, y) => !boxes.some((b) =>
          x + half.x > b.x0 && x - half.x < b.x1 && y + half.y > b.y0 && y - half.y < b.y1);
        let dx = 0;
        let dy = 0;
        if (!clear(at.x, at.y)) {
          // beside the people, the nearest place on the screen that crosses none; else above them
          const gap = 0.02;
          const xs = boxes.flatMap((b) => [b.x0 - half.x - gap, b.x1 + half.x + gap])
            .filter((x) => x - half.x > -1 && x + half.x < 1 && clear(x, at.y))
            .sort((p1, p2) => Math.abs(p1 - at.x) - Math.abs(p2 - at.x));
          if (xs.length) {
            dx = (xs[0] - at.x) * perNdc * camera.aspect;
          } else {
            const top = Math.max(...boxes.map((b) => b.y1)) + half.y + gap;
            dy = (top - at.y) * perNdc;
          }
        }
        p.label.position.copy(right).multiplyScalar(dx).addScaledVector(up, LABEL_ABOVE + dy);
        v.copy(ball).addScaledVector(right, dx).addScaledVector(up, LABEL_ABOVE + dy).project(camera);
        this.placed.names.push({ x0: v.x - half.x, x1: v.x + half.x, y0: v.y - half.y, y1: v.y + half.y });
        p.leader.visible = dx !== 0 || dy !== 0;
        if (p.leader.visible) {
          // to the near end of the name, a little below its middle
          const end = v.copy(p.label.position).addScaledVector(right, -Math.sign(dx) * LABEL_WIDTH * 0.3)
            .addScaledVector(up, -LABEL_HEIGHT * 0.25);
          p.leader.geometry.attributes.position.setXYZ(1, end.x, end.y, end.z);
          p.leader.geometry.attributes.position.needsUpdate = true;
        }
      }
    }

    label(text) {
      const THREE = this.THREE;
      const canvas = document.createElement('canvas');
      canvas.width = 256;
      canvas.height = 64;
      const g = canvas.getContext('2d');
      g.font = '28px sans-serif';
      g.fillStyle = '#7a4510';
      g.textAlign = 'center';
      g.fillText(text, 128, 40);
      const sprite = new THREE.Sprite(
        new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(canvas), depthWrite: false }),
      );
      sprite.scale.set(LABEL_WIDTH, LABEL_HEIGHT, 1);
      return sprite;
    }

    controls() {
      this.playButton = document.getElementById('play');
      this.scrub = document.getElementById('scrub');
      this.clock = document.getElementById('clock');
      this.playButton.addEventListener('click', () => (this.playing ? this.pause(true) : this.play()));
      this.scrub.addEventListener('input', () => {
        this.pause();
        this.seek(parseFloat(this.scrub.value));
      });
      this.scrub.addEventListener('change', () => this.remember());
      document.getElementById('speed').addEventListener('change', (e) => {
        this.speed = parseFloat(e.target.value);
        if (this.sound) this.sound.playbackRate = this.speed;
      });
      window.addEventListener('keydown', (e) => {
        if (e.code === 'Space' && e.target.tagName !== 'SELECT') {
          e.preventDefault();
          this.playButton.click();
        }
      });
    }

    /** Drag to turn around the character, wheel to come closer. */
    /** Where the camera looks: the middle of everywhere the characters stand during the clip and
     *  how far that spreads (walkers stay in view), or (`face`) the first character's place now. */
    stage(face) {
      if (!this.clip.times.length || !this.clip.characters.length) return { x: 0, z: 0, spread: 0, yaw: 0 };
      if (face) {
        const now = this.clip.sample(this.THREE, this.t, 0, new Float32Array(this.clip.rest.length));
        // a close look comes from in front of the character, the way it faces (its root's
        // turn about +y)
        return { x: now[0], z: now[2], spread: 0, yaw: 2 * Math.atan2(now[4], now[6]) };
      }
      if (this.clip.packed && !this.bounds) this.bounds = this.clip.packed.bounds();
      if (!this.clip.packed && (!this.bounds || this.boundsFrames !== this.clip.poses.length)) {
        this.boundsFrames = this.clip.poses.length;
        let [x0, z0, x1, z1] = [Infinity, Infinity, -Infinity, -Infinity];
        for (const frame of this.clip.poses) {
          for (const p of frame) {
            if (!p) continue;
            [x0, z0] = [Math.min(x0, p[0]), Math.min(z0, p[2])];
            [x1, z1] = [Math.max(x1, p[0]), Math.max(z1, p[2])];
          }
        }
        this.bounds = { x0, z0, x1, z1 };
      }
      const b = this.bounds;
      const x = (b.x0 + b.x1) / 2;
      const z = (b.z0 + b.z1) / 2;
      return { x, z, spread: Math.hypot(b.x1 - b.x0, b.z1 - b.z0) / 2, yaw: 0 };
    }

    orbit() {
      // the whole body, or (#face in the address, or the F key) a close look at the face
      this.body = { azimuth: 0.35, elevation: this.crowd ? 0.55 : 0.08, distance: 3.5, height: 0.92 };
      this.close = { azimuth: 0.25, elevation: 0.05, distance: 0.75, height: 1.64 };
      const face = /(?:^#|&)face(?:&|$)/.test(location.hash);
      this.view = { ...(face ? this.close : this.body) };
      window.addEventListener('keydown', (e) => {
        if (e.key === 'f' || e.key === 'F') {
          this.view = { ...(this.view.height === this.body.height ? this.close : this.body) };
        }
        if (e.key === 'c' || e.key === 'C') this.showBalance = !this.showBalance;
        if (e.key === 'm' || e.key === 'M') {
          for (const f of this.figures) {
            if (!f.avatar) continue;
            f.avatar.root.visible = !f.avatar.root.visible;
            f.nodes[0].visible = !f.avatar.root.visible;
          }
        }
      });
      let drag = null;
      this.canvas.addEventListener('pointerdown', (e) => {
        drag = { x: e.clientX, y: e.clientY, ...this.view };
        this.canvas.setPointerCapture(e.pointerId);
      });
      this.canvas.addEventListener('pointermove', (e) => {
        if (!drag) return;
        this.view.azimuth = drag.azimuth - (e.clientX - drag.x) * 0.01;
        const elevation = drag.elevation + (e.clientY - drag.y) * 0.01;
        this.view.elevation = Math.min(Math.max(elevation, -0.4), 1.4);
      });
      this.canvas.addEventListener('pointerup', () => (drag = null));
      this.canvas.addEventListener('wheel', (e) => {
        e.preventDefault();
        this.view.distance = Math.min(Math.max(this.view.distance * Math.exp(e.deltaY * 0.001), 1), 12);
      }, { passive: false });
    }

    play() {
      if (!this.data.live && this.t >= this.clip.duration) this.seek(this.clip.start);
      this.playing = true;
      this.following = !!this.data.live;
      this.last = null;
      this.playButton.textContent = '❚❚ pause';
      if (this.sound) {
        this.sound.currentTime = this.t;
        this.sound.playbackRate = this.speed;
        this.sound.play().catch(() => {});
      }
    }

    /** Stops at the current time; `remember` puts the time into the address. */
    pause(remember) {
      this.playing = false;
      this.following = false;
      this.playButton.textContent = '▶ play';
      if (this.sound) this.sound.pause();
      if (remember) this.remember();
    }

    /** The time into the page address, so that a reload or a shared link opens here. */
    remember() {
      try {
        history.replaceState(null, '', '#t=' + this.t.toFixed(3));
      } catch (e) {
        // some file:// settings forbid it; the page works without it
      }
    }

    seek(t) {
      this.t = Math.min(Math.max(t, this.clip.start), this.clip.duration);
    }

    frame(now) {
      if (this.playing) {
        if (this.following) {
          this.t = this.clip.duration;
        } else if (this.last !== null) {
          this.seek(this.t + ((now - this.last) / 1000) * this.speed);
          if (this.t >= this.clip.duration && !this.data.live) this.pause(true);
          // the sound keeps to the cursor
          if (this.sound && !this.sound.paused && Math.abs(this.sound.currentTime - this.t) > 0.08) {
            this.sound.currentTime = this.t;
          }
        }
      }
      this.last = now;
      this.draw();
      requestAnimationFrame((n) => this.frame(n));
    }

    draw() {
      const THREE = this.THREE;
      if (this.clip.times.length) {
        if (this.crowd) {
          for (let k = 0; k < this.clip.characters.length; k++) {
            this.crowd.place(k, this.clip.sample(THREE, this.t, k, this.crowdPose));
          }
          this.crowd.placed();
        }
        for (const f of this.figures) {
          const pose = this.clip.sample(THREE, this.t, f.k, f.pose);
          f.nodes[0].position.set(pose[0], pose[1], pose[2]);
          f.nodes[0].quaternion.fromArray(pose, 3);
          for (let j = 1; j < f.nodes.length; j++) f.nodes[j].quaternion.fromArray(pose, 7 + 4 * j);
          this.expression(f, this.t);
          this.balance(f);
          if (f.avatar && f.avatar.mixer) f.avatar.mixer.setTime(this.t);
          if (f.avatar && f.avatar.live) bmlrDriveLive(THREE, f.avatar, this.clip, this.t, this.clip.characters[f.k]);
        }
      }
      for (const p of this.points) if (p.keys) p.ball.position.fromArray(along(p.keys, this.t));
      const v = this.view;
      const stage = this.stage(v.height === this.close.height);
      const target = new THREE.Vector3(stage.x, v.height, stage.z);
      const distance = v.distance + 1.5 * stage.spread;
      const azimuth = v.azimuth + stage.yaw;
      this.camera.position.set(
        target.x + distance * Math.sin(azimuth) * Math.cos(v.elevation),
        target.y + distance * Math.sin(v.elevation),
        target.z + distance * Math.cos(azimuth) * Math.cos(v.elevation),
      );
      this.camera.lookAt(target);
      this.placeLabels();
      this.renderer.render(this.scene, this.camera);
      this.scrub.min = String(this.clip.start);
      this.scrub.max = String(Math.max(this.clip.duration, this.clip.start + 0.001));
      this.scrub.value = String(this.t);
      this.clock.textContent = fmt(this.t) + ' / ' + fmt(this.clip.duration);
      this.moveCursor();
      this.showFeedbackUpTo(this.t);
      if (!this.drawn && this.avatarsLoading === 0) {
        this.drawn = true;
        // with #timing in the address, the console says when (its log lines carry the real
        // time, also under a headless browser's virtual time)
        if (/(?:^#|&)timing(?:&|$)/.test(location.hash)) console.info('bmlr view: ready');
        document.title = 'bmlr view: ready';
        if (this.placed) document.documentElement.dataset.placed = JSON.stringify(this.placed);
      }
    }

    /** Puts the timeline picture in place, with a cursor line over it; a click seeks. */
    setTimeline(timeline) {
      if (!timeline) return;
      const box = document.getElementById('timeline');
      box.innerHTML = timeline.svg;
      this.axis = timeline.axis;
      const svg = box.querySelector('svg');
      if (!svg) return;
      const ns = 'http://www.w3.org/2000/svg';
      this.cursor = document.createElementNS(ns, 'line');
      this.cursor.setAttribute('y1', '0');
      this.cursor.setAttribute('y2', svg.getAttribute('height'));
      this.cursor.setAttribute('stroke', '#d03030');
      this.cursor.setAttribute('stroke-width', '2');
      svg.appendChild(this.cursor);
      svg.addEventListener('click', (e) => {
        const x = e.clientX - svg.getBoundingClientRect().left;
        this.pause();
        this.seek(this.axis.t0 + (x - this.axis.left) / this.axis.px_per_s);
        this.remember();
      });
      this.cursorAt = null;
    }

    moveCursor() {
      if (!this.cursor || this.cursorAt === this.t) return;
      this.cursorAt = this.t;
      const x = this.axis.left + (this.t - this.axis.t0) * this.axis.px_per_s;
      this.cursor.setAttribute('x1', x.toFixed(1));
      this.cursor.setAttribute('x2', x.toFixed(1));
      const box = document.getElementById('timeline');
      if (x < box.scrollLeft + 40 || x > box.scrollLeft + box.clientWidth - 40) {
        box.scrollLeft = Math.max(x - box.clientWidth / 3, 0);
      }
    }

    /** One feedback message ({time, kind, text}); messages arrive in time order. */
    addFeedback(m) {
      const li = document.createElement('li');
      li.className = m.kind;
      li.hidden = true;
      const at = document.createElement('span');
      at.className = 'at';
      at.textContent = m.time.toFixed(3);
      // the namespace declarations repeat on every line: the list leaves them out
      li.append(at, m.text.replace(/ xmlns(:\w+)?="[^"]*"/g, ''));
      document.getElementById('feedback').appendChild(li);
      this.feedback.push({ time: m.time, li });
      if (this.feedback.length === 1) this.refreshFeedbackEmpty();
    }

    refreshFeedbackEmpty() {
      const list = document.getElementById('feedback');
      const empty = list.querySelector('.empty');
      if (this.feedback.length && empty) empty.remove();
      if (!this.feedback.length && !empty) {
        const li = document.createElement('li');
        li.className = 'empty';
        li.textContent = 'no feedback yet';
        list.appendChild(li);
      }
    }

    /** Shows the messages sent by `t`, to the millisecond the page prints times in: at
     *  `#t=0.821` the stroke the feedback reports at 0.821 (really 0.8213) is in the list. */
    showFeedbackUpTo(t) {
      const upTo = Math.round(t * 1000) + 0.5;
      let n = 0;
      while (n < this.feedback.length && this.feedback[n].time * 1000 < upTo) n++;
      if (n === this.shown) return;
      const [lo, hi] = n > this.shown ? [this.shown, n] : [n, this.shown];
      for (let i = lo; i < hi; i++) this.feedback[i].li.hidden = i >= n;
      this.shown = n;
      if (n > 0) this.feedback[n - 1].li.scrollIntoView({ block: 'nearest' });
    }

    /** Live: frames, feedback and the timeline arrive over a WebSocket as they happen. */
    connect() {
      const socket = new WebSocket('ws://' + location.host + '/live');
      socket.onmessage = (e) => {
        const m = JSON.parse(e.data);
        if (m.frame) this.clip.push(m.frame, m.avatars);
        if (m.feedback) this.addFeedback(m.feedback);
        if (m.timeline) this.setTimeline(m.timeline);
      };
      socket.onclose = () => {
        document.getElementById('what').textContent = this.data.title + ' (disconnected)';
      };
      this.play();
    }
  }
})();
