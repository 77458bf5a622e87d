"""The land cover a city's input maps (``<name>.ground.geojson``, facadecli.city.landcover)
drawn on the viewer's ground: each kind one flat mesh with its own material (water dark
and glossy with small waves, lawns, a wood's floor, pitches, sand, car parks of asphalt),
trees in woods and parks, none on water; the street trees, dashes and lamps the
footprint rules place (facadecli.viewer.ground) kept only where no land cover is mapped.

:data:`COVER` holds the pure functions over the plan's grid (run in node by
tests/test_ground.py); :data:`COVER_DRAWN` the three.js side, part of the viewer."""

from __future__ import annotations

# The rules (docs/reference/materials.md, "Land cover"):
# - the kinds are drawn in COVER_KINDS' order, a later kind over an earlier one (a pond in
#   a park is water, a pitch in a park a pitch);
# - a cell of the plan is of the kind whose polygons hold its centre (even-odd: a
#   multipolygon's holes are not), none where nothing is mapped;
# - a wood has a tree about every WOOD_EVERY metres, a park every PARK_EVERY with a share
#   PARK_CLEARINGS left open, each on a jittered lattice (the same each time), TREE_CLEAR
#   metres or more from a building and from water, a pitch or a car park.
COVER = """
const COVER_KINDS = ['wood', 'grass', 'park', 'sand', 'pitch', 'parking', 'water'];
const WOOD_EVERY = 4.5, PARK_EVERY = 13, PARK_CLEARINGS = 0.35, TREE_CLEAR = 2.5;
// A number in [0, 1) of two integers and a salt, the same each time (a lattice's jitter)
function latticeHash(i, j, salt) {
  let h = Math.imul(i, 374761393) ^ Math.imul(j, 668265263) ^ Math.imul(salt + 1, 362437);
  h = Math.imul(h ^ (h >>> 13), 1274126177);
  return ((h ^ (h >>> 16)) >>> 0) / 4294967296;
}
// The kind of each cell of a grid (0 none, else COVER_KINDS' index + 1): ``polygons``
// [{kind, rings: [[[x, y], ...], ...]}] in cells (x along a row, y down the rows, a cell's
// centre at +0.5), filled by scanlines through the cells' centres, even-odd
function coverCells(polygons, columns, rows) {
  const cover = new Uint8Array(columns * rows);
  const rank = polygon => COVER_KINDS.indexOf(polygon.kind);
  const drawn = polygons.filter(polygon => rank(polygon) >= 0)
    .map((polygon, order) => [polygon, order])
    .sort((a, b) => rank(a[0]) - rank(b[0]) || a[1] - b[1]);
  for (const [{kind, rings}] of drawn) {
    const code = COVER_KINDS.indexOf(kind) + 1;
    let top = Infinity, bottom = -Infinity;
    for (const ring of rings) for (const point of ring) {
      top = Math.min(top, point[1]); bottom = Math.max(bottom, point[1]);
    }
    const first = Math.max(0, Math.floor(top)), last = Math.min(rows - 1, Math.ceil(bottom));
    for (let row = first; row <= last; row++) {
      const y = row + 0.5, crossings = [];
      for (const ring of rings) for (let i = 0, j = ring.length - 1; i < ring.length; j = i++) {
        const [x1, y1] = ring[j], [x2, y2] = ring[i];
        if ((y1 > y) !== (y2 > y)) crossings.push(x1 + (y - y1) / (y2 - y1) * (x2 - x1));
      }
      crossings.sort((a, b) => a - b);
      for (let k = 0; k + 1 < crossings.length; k += 2) {
        const from = Math.max(0, Math.ceil(crossings[k] - 0.5));
        const to = Math.min(columns - 1, Math.floor(crossings[k + 1] - 0.5));
        for (let column = from; column <= to; column++) cover[row * columns + column] = code;
      }
    }
  }
  return cover;
}
// The trees of the woods and parks (see the rules): cells, ascending. ``near``: each
// cell's distance to the nearest building, in cells (groundKinds')
function coverTreeCells(cover, near, columns, rows, cell) {
  const code = kind => COVER_KINDS.indexOf(kind) + 1, trees = [];
  const clearOf = [code('water'), code('pitch'), code('parking')];
  for (const [kind, every, clearings] of [['wood', WOOD_EVERY, 0], ['park', PARK_EVERY,
                                                                     PARK_CLEARINGS]]) {
    const step = every / cell, wanted = code(kind);
    for (let j = 0; j * step < rows; j++) for (let i = 0; i * step < columns; i++) {
      const column = Math.round((i + 0.5 + 0.7 * (latticeHash(i, j, wanted) - 0.5)) * step);
      const row = Math.round((j + 0.5 + 0.7 * (latticeHash(j, i, wanted + 7) - 0.5)) * step);
      if (column >= columns || row >= rows) continue;
      const at = row * columns + column;
      if (cover[at] !== wanted || near[at] * cell < TREE_CLEAR) continue;
      if (clearings && latticeHash(i, j, 99) < clearings) continue;
      if (clearOf.some(other => besideKind(cover, columns, cell, at, other, TREE_CLEAR))) continue;
      trees.push(at);
    }
  }
  return trees.sort((a, b) => a - b);
}
"""

# the three.js side: the meshes of the land cover and its materials, and the hooks
# show() and groundRegions() call
COVER_DRAWN = """
let landCover = null;  // the GeoJSON of the model shown, or null
// The land cover beside the model of the script element ``id`` (its ``id-ground``), if any
function landCoverOf(id) {
  const element = document.getElementById(id + '-ground');
  if (!element) return null;
  try { return JSON.parse(new TextDecoder().decode(bytesOf(id + '-ground'))); }
  catch (error) { return null; }
}
// a kind's look: its colour (linear), roughness, and how far above the ground it lies
// (metres, a kind drawn later higher, so overlaps never flicker)
const COVER_LOOKS = {
  wood: [0.030, 0.045, 0.020, 0.95], grass: [0.068, 0.085, 0.034, 0.9],
  park: [0.050, 0.080, 0.030, 0.9], sand: [0.42, 0.36, 0.25, 0.95],
  pitch: [0.045, 0.100, 0.030, 0.8], parking: [0.045, 0.045, 0.048, 0.85],
  water: [0.010, 0.022, 0.028, 0.06]};
const COVER_LIFT = 0.015, WAVE = 11;  // metres: a kind above the one before; a wave tile
function speckPicture(seed, size = 64) {  // grey specks round 1: a lawn's or asphalt's grain
  const random = seeded(seed), data = new Uint8Array(size * size * 4);
  for (let at = 0; at < size * size; at++) {
    const tone = 200 + 55 * random();
    data.set([tone, tone, tone, 255], at * 4);
  }
  const picture = new THREE.DataTexture(data, size, size);
  picture.wrapS = picture.wrapT = THREE.RepeatWrapping;
  picture.magFilter = THREE.LinearFilter; picture.minFilter = THREE.LinearMipmapLinearFilter;
  picture.generateMipmaps = true; picture.repeat.set(1 / 3, 1 / 3);
  picture.needsUpdate = true;
  return picture;
}
function wavePicture(size = 64) {  // a normal map of long low ripples crossing, tiling
  const data = new Uint8Array(size * size * 4), k = 2 * Math.PI / size;
  const ripples = [[1, 0, 0.6], [1, 2, 0.35], [-2, 1, 0.25], [3, -1, 0.12]];  // x, y, height
  for (let y = 0; y < size; y++) for (let x = 0; x < size; x++) {
    let dx = 0, dy = 0;
    for (const [a, b, h] of ripples) {
      const slope = h * Math.cos(k * (a * x + b * y));
      dx += slope * a; dy += slope * b;
    }
    const n = new THREE.Vector3(-dx * 0.12, -dy * 0.12, 1).normalize();
    data.set([(n.x * 0.5 + 0.5) * 255, (n.y * 0.5 + 0.5) * 255, (n.z * 0.5 + 0.5) * 255, 255],
             (y * size + x) * 4);
  }
  const picture = new THREE.DataTexture(data, size, size);
  picture.wrapS = picture.wrapT = THREE.RepeatWrapping;
  picture.magFilter = THREE.LinearFilter; picture.minFilter = THREE.LinearMipmapLinearFilter;
  picture.generateMipmaps = true; picture.repeat.set(1 / WAVE, 1 / WAVE);
  picture.needsUpdate = true;
  return picture;
}
const coverMaterials = (() => {
  const specks = speckPicture(19), materials = {};
  for (const [kind, [r, g, b, roughness]] of Object.entries(COVER_LOOKS)) {
    const water = kind === 'water';
    const material = new THREE.MeshStandardMaterial({
      color: new THREE.Color().setRGB(r, g, b), roughness, map: water ? null : specks,
      normalMap: water ? wavePicture() : null, polygonOffset: true,
      polygonOffsetFactor: -1 - COVER_KINDS.indexOf(kind), polygonOffsetUnits: -2});
    if (water) material.normalScale.set(0.5, 0.5);
    endsInHaze(material);
    materials[kind] = material;
  }
  return materials;
})();
const coverParts = new THREE.Group();
scene.add(coverParts);
// The land cover's polygons in the glTF frame (x east, z south, metres from the models'
// origin): [{kind, rings: [[[x, z], ...], ...]}], one entry a polygon
function coverPolygons(collection) {
  const [east, north] = collection.origin || [0, 0], unit = collection.metres_per_unit || 1;
  const polygons = [];
  for (const feature of collection.features || []) {
    const kind = feature.properties && feature.properties.kind, geometry = feature.geometry;
    if (!COVER_LOOKS[kind] || !geometry) continue;
    const parts = geometry.type === 'Polygon' ? [geometry.coordinates] : geometry.coordinates;
    for (const part of parts) {
      polygons.push({kind, rings: part.map(ring => ring.map(
        ([x, y]) => [x * unit - east, -(y * unit - north)]))});
    }
  }
  return polygons;
}
// One flat mesh a kind (its parts merged: one draw call a kind), at ``y``
function placeLandCover(polygons, y) {
  for (const part of [...coverParts.children]) { coverParts.remove(part); part.geometry.dispose(); }
  const byKind = new Map();
  for (const {kind, rings} of polygons) {
    const shape = new THREE.Shape(rings[0].map(([x, z]) => new THREE.Vector2(x, -z)));
    shape.holes = rings.slice(1).map(ring => new THREE.Path(ring.map(
      ([x, z]) => new THREE.Vector2(x, -z))));
    const geometry = new THREE.ShapeGeometry(shape).rotateX(-Math.PI / 2);
    byKind.set(kind, [...(byKind.get(kind) || []), geometry]);
  }
  for (const kind of COVER_KINDS) {
    if (!byKind.has(kind)) continue;
    const mesh = new THREE.Mesh(mergeGeometries(byKind.get(kind)), coverMaterials[kind]);
    for (const geometry of byKind.get(kind)) geometry.dispose();
    mesh.position.y = y + COVER_LIFT * (COVER_KINDS.indexOf(kind) + 1);
    mesh.receiveShadow = true;
    mesh.name = 'land cover: ' + kind;
    coverParts.add(mesh);
  }
}
// The land cover on a district's plan (groundRegions' grid: ``wide`` x ``deep`` cells of
// ``cell`` metres, row 0 at the glTF +z edge ``top``, column 0 at ``left``): each cell's
// kind (coverCells); ``open(at)``, whether the footprint rules may place a street tree, a
// dash or a lamp there (nothing mapped); and the trees of the woods and parks, on a grid of
// TREE_CELL metres over the plan and all the land cover round it ([x, z], glTF), so a
// wood past the plan's margin has its trees too
const TREE_CELL = 1;
function coverPlan(plan, left, top, wide, deep, cell) {
  const polygons = landCover ? coverPolygons(landCover) : [];
  const inCells = (from, upper, size) => polygons.map(({kind, rings}) => ({kind,
    rings: rings.map(ring => ring.map(([x, z]) => [(x - from) / size, (upper - z) / size]))}));
  const cover = coverCells(inCells(left, top, cell), wide, deep);
  let west = left, east = left + wide * cell, south = top, north = top - deep * cell;
  for (const {rings} of polygons) for (const [x, z] of rings[0]) {
    west = Math.min(west, x); east = Math.max(east, x);
    north = Math.min(north, z); south = Math.max(south, z);
  }
  const step = Math.max(cell, TREE_CELL);
  const columns = Math.ceil((east - west) / step), rows = Math.ceil((south - north) / step);
  const near = new Float32Array(columns * rows).fill(1e9);  // to the buildings, in steps
  for (let row = 0; row < rows; row++) for (let column = 0; column < columns; column++) {
    const c = Math.floor((west + (column + 0.5) * step - left) / cell);
    const r = Math.floor((top - (south - (row + 0.5) * step)) / cell);
    if (c >= 0 && c < wide && r >= 0 && r < deep) {
      near[row * columns + column] = plan.near[r * wide + c] * cell / step;
    }
  }
  const around = coverCells(inCells(west, south, step), columns, rows);
  const trees = polygons.length ? coverTreeCells(around, near, columns, rows, step) : [];
  return {polygons, cover, open: at => !cover[at], trees: trees.map(at => [
    west + (at % columns + 0.5) * step, south - (Math.floor(at / columns) + 0.5) * step])};
}
// What the page says of the land cover drawn (data-cover, read by the browser tests): the
// share of the plan (not its margin) of each kind, the trees of woods and parks, the meshes
function coverCounts(covered, wide, margin, rows, columns) {
  const shares = Object.fromEntries(COVER_KINDS.map(kind => [kind, 0]));
  for (let row = margin; row < margin + rows; row++) {
    for (let column = margin; column < margin + columns; column++) {
      const code = covered.cover[row * wide + column];
      if (code) shares[COVER_KINDS[code - 1]]++;
    }
  }
  for (const kind of COVER_KINDS) {
    shares[kind] = Math.round(shares[kind] / (columns * rows) * 1000) / 1000;
  }
  return {shares, trees: covered.trees.length, meshes: coverParts.children.length};
}
"""
