"""The ground under a district in the viewer, as a town has it: what each place of the
district's plan is (a street, a pavement, a kerb, a back yard), the street trees and the
road's centre-line dashes. Pure functions over the plan's grid (JavaScript, part of
:data:`facadecli.viewer.VIEWER`); the page draws what they return."""

from __future__ import annotations

# The rules (docs/reference/materials.md, "The ground under a district"):
# - every distance is Euclidean (distanceField), so a pavement rounds a building's corner;
# - a place is street if it is reached from the town round the district (the plan's edge)
#   through open ground at least PASSAGE metres from every building (a gap narrower than
#   twice that, between two houses, is not a street), or lies within PASSAGE of such a
#   place; elsewhere it is a yard (a courtyard, a back garden, a gap between houses);
# - a street has a pavement PAVEMENT metres wide along its walls, WIDE_PAVEMENT where the
#   street runs on ROOM metres past it (a wide street or the town's edge), then a kerb
#   KERB wide, then asphalt; the land round the district is such a street, to the haze;
# - a yard has a path YARD_PATH wide along its walls, then grass;
# - round detached houses (DETACHED_MOST m² or less) the street runs between blocks of
#   their plots (plotBlocks: the plots whose houses stand closest joined first, up to
#   BLOCK_PLOTS m² a block), not round each house: asphalt LANE metres either side of
#   where two blocks meet, a kerb, a SIDEWALK, then the garden's lawn, a path YARD_PATH
#   wide round the house and a drive DRIVE wide from the road to it (driveCells);
# - those streets lead somewhere (joinedStreets): their pieces, and each cluster of houses
#   no street reaches, joined into one network along the boundaries between blocks'
#   plots; a street that still stops short ends in a turning head TURNING_HEAD round;
# - past its pavement a street is asphalt, to ROAD_HALF[1] metres from the walls at most
#   (the middle of a street 24 m wide), and a paved square farther out, where buildings
#   close the place in: its enclosure (the share of RAYS_AROUND rays from it that meet a
#   wall within SQUARE_REACH metres, of those that stay in the plan) at least
#   ROAD_ENCLOSED for a road, ENCLOSED for a square; open land no walls close in is grass,
#   the lawns of a sparse town (by distance alone, a town of detached houses 30-100 m
#   apart was all paved square);
# - a road meets a lawn at a kerb (kerbLawns);
# - a tree every TREE_EVERY metres or more in pits along the wide pavements of roads,
#   TREE_LINE metres from the walls, where the pavement runs straight for TREE_STRAIGHT
#   metres (not on the ring of paving round a detached house), and scattered on the open
#   lawns (treeCells); a dash DASH metres long every DASH_EVERY metres along a street's
#   centre (the ridge of the distance to its walls), where the street is ROAD_HALF metres
#   from its walls;
# - a street lamp every LAMP_EVERY metres or more, on a pavement LAMP_KERB metres short of
#   its kerb where asphalt follows, LAMP_CLEAR metres or more from a tree, its arm over the
#   road;
# - a bench every BENCH_EVERY metres or more on the paving at a lawn's edge, facing the
#   lawn, away from roads, trees and lamps (benchCells).
GROUND = """
const PAVEMENT = 2.5, WIDE_PAVEMENT = 4.5, KERB = 0.2, PASSAGE = 3, YARD_PATH = 1;
const ROOM = 6, GROUND_MARGIN = 14, LANE = 3, SIDEWALK = 2;
const TREE_LINE = 3.4, TREE_EVERY = 9, DASH = 3, DASH_EVERY = 7.5, ROAD_HALF = [3.5, 12];
const LAMP_EVERY = 30, LAMP_KERB = 0.6, LAMP_CLEAR = 3;
const TREE_STRAIGHT = 14, LAWN_TREE_WALL = 6, LAWN_TREE_EDGE = 2, LAWN_TREE_EVERY = 18;
const SQUARE_REACH = 40, RAYS_AROUND = 32, ENCLOSED = 0.5, ROAD_ENCLOSED = 0.3;
// The exact Euclidean distance of each cell of a grid (row by row, ``columns`` a row) to
// the nearest cell set in ``seeds``, in cells: the lower envelope of parabolas
// (Felzenszwalb and Huttenlocher), down each column, then along each row. A chamfer (steps
// of 1 and the square root of 2) drew octagons round a building's corner. With
// ``nearest`` (an Int32Array as long), each cell's nearest seed (its index) is put there.
function distanceField(seeds, columns, rows, nearest = null) {
  const FAR = 1e20, squared = new Float64Array(columns * rows);
  for (let at = 0; at < columns * rows; at++) squared[at] = seeds[at] ? 0 : FAR;
  if (nearest) for (let at = 0; at < columns * rows; at++) nearest[at] = seeds[at] ? at : -1;
  const size = Math.max(columns, rows);
  const f = new Float64Array(size), lowest = new Int32Array(size);
  const from = new Float64Array(size + 1), whose = new Int32Array(size);
  const line = (start, step, count) => {
    for (let i = 0; i < count; i++) f[i] = squared[start + i * step];
    if (nearest) for (let i = 0; i < count; i++) whose[i] = nearest[start + i * step];
    let k = 0;
    lowest[0] = 0; from[0] = -Infinity; from[1] = Infinity;
    for (let q = 1; q < count; q++) {
      let s;
      for (;;) {
        const p = lowest[k];
        s = (f[q] + q * q - f[p] - p * p) / (2 * (q - p));
        if (s > from[k]) break;
        k--;
      }
      k++; lowest[k] = q; from[k] = s; from[k + 1] = Infinity;
    }
    k = 0;
    for (let q = 0; q < count; q++) {
      while (from[k + 1] < q) k++;
      const p = lowest[k];
      squared[start + q * step] = (q - p) * (q - p) + f[p];
      if (nearest) nearest[start + q * step] = whose[p];
    }
  };
  for (let column = 0; column < columns; column++) line(column, columns, rows);
  for (let row = 0; row < rows; row++) line(row * columns, 1, columns);
  const distance = new Float32Array(columns * rows);
  for (let at = 0; at < columns * rows; at++) distance[at] = Math.sqrt(squared[at]);
  return distance;
}
// The cells reached from the grid's edge through cells whose ``near`` is at least ``least``
// (four neighbours a cell): the open ground a street runs through.
function reachedFromEdge(near, columns, rows, least) {
  const reached = new Uint8Array(columns * rows), queue = new Int32Array(columns * rows);
  let head = 0, tail = 0;
  const visit = at => {
    if (!reached[at] && near[at] >= least) { reached[at] = 1; queue[tail++] = at; }
  };
  for (let column = 0; column < columns; column++) {
    visit(column); visit((rows - 1) * columns + column);
  }
  for (let row = 0; row < rows; row++) { visit(row * columns); visit(row * columns + columns - 1); }
  while (head < tail) besideEach(queue[head++], columns, rows, visit);
  return reached;
}
// Calls visit with each of the (up to) four cells beside the cell at, on a grid of
// columns x rows: the step of every flood over the grid.
function besideEach(at, columns, rows, visit) {
  const column = at % columns;
  if (column > 0) visit(at - 1);
  if (column < columns - 1) visit(at + 1);
  if (at >= columns) visit(at - columns);
  if (at < (rows - 1) * columns) visit(at + columns);
}
// Whether the street at ``at`` runs on ROOM metres past it, away from its nearest wall
// (the way the distance grows): a wide street, or the open town round the district
function roomy(near, columns, rows, cell, at) {
  const column = at % columns, row = (at - column) / columns;
  const value = (c, r) => c < 0 || c >= columns || r < 0 || r >= rows ? Infinity
    : near[r * columns + c];
  let dx = value(column + 2, row) - value(column - 2, row);
  let dy = value(column, row + 2) - value(column, row - 2);
  if (!Number.isFinite(dx) || !Number.isFinite(dy)) return true;  // at the grid's edge
  const length = Math.hypot(dx, dy);
  if (length < 1e-6) return false;  // on a ridge: the middle of a street
  dx /= length; dy /= length;
  const probe = ROOM / cell;
  const there = value(Math.round(column + dx * probe), Math.round(row + dy * probe));
  return there * cell >= near[at] * cell + ROOM - 1.5;
}
// How closed in by walls each place is, 0..1: of RAYS_AROUND rays from it, evenly round,
// the share that meets a building within SQUARE_REACH metres, of those that do not leave
// the plan first (what lies past the district is unknown), or of half the rays where
// more leave (a few rays left drew streaks of square along their directions). Each ray
// marches along the distance field (``near``, cells), a step as long as the way is clear:
// a few steps a ray. Taken every ENCLOSURE_STEP metres and interpolated between, so a
// boundary between square and lawn runs smooth, not in the rays' jagged fans.
const ENCLOSURE_STEP = 4;
function enclosureField(near, columns, rows, cell) {
  const reach = SQUARE_REACH / cell, step = Math.max(1, Math.round(ENCLOSURE_STEP / cell));
  const across = Math.ceil((columns - 1) / step) + 1, down = Math.ceil((rows - 1) / step) + 1;
  const coarse = new Float32Array(across * down);
  const directions = Array.from({length: RAYS_AROUND}, (_, ray) => {
    const angle = 2 * Math.PI * (ray + 0.5) / RAYS_AROUND;
    return [Math.cos(angle), Math.sin(angle)];
  });
  for (let j = 0; j < down; j++) for (let i = 0; i < across; i++) {
    const column = Math.min(i * step, columns - 1), row = Math.min(j * step, rows - 1);
    let walls = 0, out = 0;
    for (const [dx, dy] of directions) {
      for (let along = 0; along <= reach;) {
        const x = Math.round(column + dx * along), y = Math.round(row + dy * along);
        if (x < 0 || x >= columns || y < 0 || y >= rows) { out++; break; }
        const clear = near[y * columns + x];
        if (clear < 1) { walls++; break; }
        along += Math.max(1, clear - 1);
      }
    }
    coarse[j * across + i] = walls / Math.max(RAYS_AROUND - out, RAYS_AROUND / 2);
  }
  return at => {  // bilinear between the four places taken round ``at``
    const column = at % columns, row = (at - column) / columns;
    const u = column / step, v = row / step;
    const i = Math.min(Math.floor(u), across - 2), j = Math.min(Math.floor(v), down - 2);
    const fu = across > 1 ? u - i : 0, fv = down > 1 ? v - j : 0;
    const value = (a, b) => coarse[Math.min(b, down - 1) * across + Math.min(a, across - 1)];
    const top = value(i, j) + (value(i + 1, j) - value(i, j)) * fu;
    const bottom = value(i, j + 1) + (value(i + 1, j + 1) - value(i, j + 1)) * fu;
    return top + (bottom - top) * fv;
  };
}
// The buildings of a plan: each connected piece of its built cells (four neighbours) a
// number from 1 -> {piece: each cell's (0 open), areas: each piece's cells (areas[0] 0)}
function buildingPieces(building, columns, rows) {
  const piece = new Int32Array(columns * rows), areas = [0];
  const queue = new Int32Array(columns * rows);
  for (let start = 0; start < columns * rows; start++) {
    if (!building[start] || piece[start]) continue;
    const id = areas.length;
    let head = 0, tail = 0;
    const visit = at => { if (building[at] && !piece[at]) { piece[at] = id; queue[tail++] = at; } };
    visit(start);
    while (head < tail) besideEach(queue[head++], columns, rows, visit);
    areas.push(tail);
  }
  return {piece, areas};
}
// The buildings of a plan as buildingPieces, those less than ROW_GAP metres apart one
// piece (a terrace of houses whose footprints do not quite touch is a row, not detached
// houses): a piece's area counts its built cells alone
const ROW_GAP = 3;
function buildingRows(building, near, columns, rows, cell) {
  const joined = near.map(distance => distance * cell <= ROW_GAP / 2 ? 1 : 0);
  const {piece} = buildingPieces(joined, columns, rows);
  const areas = [0];
  for (let at = 0; at < piece.length; at++) {
    if (!building[at]) { piece[at] = 0; continue; }
    while (areas.length <= piece[at]) areas.push(0);
    areas[piece[at]]++;
  }
  return {piece, areas};
}
// Detached houses stand in gardens along streets (a town of them was a ring of paving and
// a ring road round each house, at fixed distances from its walls). Each open place
// belongs to the plot of its nearest building (``owner``: a piece of buildingPieces). A
// building of DETACHED_MOST m² or less is detached: the plots of two detached buildings
// that meet join one block, the narrowest gap between them first (a shed in a garden,
// the side gap between neighbours in a row, then back gardens), while the block's plots
// hold BLOCK_PLOTS m² or less of the land within ROAD_REACH metres of a wall; a street
// runs where two blocks' plots meet (or a detached house's plot meets another building's),
// within ROAD_REACH metres of the walls (past it open land, no road). A building whose
// ground within GARDEN_ROUND metres of its walls is closed in by others (enclosureField)
// GARDEN_ENCLOSED or more on average stands in a town's street, paved to its walls, not
// in a garden (the demo district's houses 8 m apart; Kotka's stand in open land, about
// 0.1 to 0.4, as do 100 houses 45 m apart, about 0.3). Returns each
// piece's block (a piece not detached is its own) and whether each piece is detached.
const DETACHED_MOST = 400, BLOCK_PLOTS = 10000, ROAD_REACH = 30;
const GARDEN_ROUND = 10, GARDEN_ENCLOSED = 0.7;
function plotBlocks(owner, near, areas, columns, rows, cell, enclosed) {
  const pieces = areas.length, square = cell * cell, reach = ROAD_REACH / cell;
  const closed = new Float64Array(pieces), round = new Float64Array(pieces);
  for (let at = 0; at < columns * rows; at += 3) {  // every third place is enough
    if (!near[at] || near[at] * cell > GARDEN_ROUND) continue;
    closed[owner[at]] += enclosed(at); round[owner[at]]++;
  }
  const detached = areas.map((area, id) => id > 0 && area * square <= DETACHED_MOST
    && closed[id] < GARDEN_ENCLOSED * round[id]);
  const plots = new Float64Array(pieces);
  for (let at = 0; at < columns * rows; at++) {
    if (near[at] > 0 && near[at] <= reach) plots[owner[at]] += square;
  }
  const narrowest = new Map();  // two detached plots that meet -> the narrowest gap between them
  const meet = (at, next) => {
    const a = owner[at], b = owner[next];
    if (a === b || !detached[a] || !detached[b] || !near[at] || !near[next]) return;
    const key = Math.min(a, b) * pieces + Math.max(a, b), gap = Math.min(near[at], near[next]);
    if (!(narrowest.get(key) <= gap)) narrowest.set(key, gap);
  };
  for (let at = 0; at < columns * rows; at++) {
    if (at % columns < columns - 1) meet(at, at + 1);
    if (at < (rows - 1) * columns) meet(at, at + columns);
  }
  const block = Int32Array.from({length: pieces}, (_, id) => id);
  const find = id => { while (block[id] !== id) id = block[id] = block[block[id]]; return id; };
  const pairs = [...narrowest.entries()].sort((p, q) => p[1] - q[1] || p[0] - q[0]);
  for (const [key] of pairs) {
    const a = find(Math.floor(key / pieces)), b = find(key % pieces);
    if (a === b || plots[a] + plots[b] > BLOCK_PLOTS) continue;
    const [kept, joined] = a < b ? [a, b] : [b, a];
    block[joined] = kept; plots[kept] += plots[joined];
  }
  return {block: Int32Array.from({length: pieces}, (_, id) => find(id)), detached};
}
// The middle of each street between blocks (plotBlocks): the open places where the plot
// of a block meets another's, one of them detached, within ROAD_REACH metres of the walls
// -> {middle, boundary}: boundary, every place where two such plots meet, however far out
function streetMiddles(owner, near, blocks, columns, rows, cell) {
  const {block, detached} = blocks, middle = new Uint8Array(columns * rows);
  const boundary = new Uint8Array(columns * rows), reach = ROAD_REACH / cell;
  const mark = (at, next) => {
    const a = owner[at], b = owner[next];
    if (!near[at] || !near[next] || block[a] === block[b]) return;
    if (!detached[a] && !detached[b]) return;
    boundary[at] = 1;
    if (near[at] <= reach) middle[at] = 1;
  };
  for (let at = 0; at < columns * rows; at++) {
    if (at % columns < columns - 1) mark(at, at + 1);
    if (at < (rows - 1) * columns) mark(at, at + columns);
  }
  return {middle, boundary};
}
// Calls visit with each of the (up to) eight cells round the cell at: the step along a
// street's middle, a line one or two cells thick that runs any way
function aroundEach(at, columns, rows, visit) {
  const column = at % columns, row = (at - column) / columns;
  for (let y = Math.max(0, row - 1); y <= Math.min(rows - 1, row + 1); y++) {
    for (let x = Math.max(0, column - 1); x <= Math.min(columns - 1, column + 1); x++) {
      if (x !== column || y !== row) visit(y * columns + x);
    }
  }
}
// The blocks of houses (one with a detached building of OUTBUILDING m² or more) no
// street's middle passes (none in their plots nor beside them): a cluster of houses more
// than ROAD_REACH from any other block -> for each, the places of its plots ACCESS
// metres (within a cell) from its walls, where its access road may end
const ACCESS = 12;
function unservedBlocks(streets, owner, near, pieces, blocks, columns, rows, cell) {
  const {middle} = streets, {areas} = pieces, {block, detached} = blocks;
  const served = new Uint8Array(areas.length), housed = new Uint8Array(areas.length);
  for (let id = 1; id < areas.length; id++) {
    if (detached[id] && areas[id] * cell * cell >= OUTBUILDING) housed[block[id]] = 1;
  }
  for (let at = 0; at < columns * rows; at++) {
    if (!middle[at]) continue;
    served[block[owner[at]]] = 1;
    besideEach(at, columns, rows, next => { if (near[next]) served[block[owner[next]]] = 1; });
  }
  const places = new Map();  // a block -> its places
  for (let at = 0; at < columns * rows; at++) {
    const b = block[owner[at]];
    if (!near[at] || !housed[b] || served[b] || Math.abs(near[at] * cell - ACCESS) > cell / 2) {
      continue;
    }
    places.set(b, [...(places.get(b) || []), at]);
  }
  return [...places.values()];
}
// Streets that lead somewhere. The middles of streetMiddles stop ROAD_REACH metres from
// the walls, so a street running out into open land ended in a stub there, and a
// cluster of houses more than ROAD_REACH from any other block had no street at all. The
// middles' pieces (eight neighbours) and the unserved blocks (unservedBlocks) are joined
// into one network, the cheapest joins first: one search from every piece at once over
// the open ground SIDEWALK or more past a road's kerb from the walls (Dijkstra; a step
// along the boundaries between blocks' plots, where a street runs, costs a third of one
// across a plot), a join where two pieces' searches meet, Kruskal over the joins
// (Mehlhorn's Steiner tree). A street that still stops short (at the reach, or at an
// unserved block) ends in a turning head: asphalt TURNING_HEAD metres round its end
// (its middle a disc TURNING_HEAD - LANE round it). A street reaching the plan's edge
// goes on into the town. -> the network's middle (a mask)
const TURNING_HEAD = 6, ACROSS_PLOTS = 3;
function joinedStreets(streets, owner, near, pieces, blocks, columns, rows, cell) {
  const {middle, boundary} = streets, count = columns * rows, reach = ROAD_REACH / cell;
  const network = Uint8Array.from(middle), joined = new Uint8Array(count);
  const wave = new Int32Array(count).fill(-1), queue = new Int32Array(count);
  let parts = 0;
  for (let start = 0; start < count; start++) {  // the middles' pieces
    if (!middle[start] || wave[start] >= 0) continue;
    let head = 0, tail = 0;
    wave[start] = parts; queue[tail++] = start;
    while (head < tail) {
      aroundEach(queue[head++], columns, rows, next => {
        if (middle[next] && wave[next] < 0) { wave[next] = parts; queue[tail++] = next; }
      });
    }
    parts++;
  }
  // an unserved block's places a piece; its road ends at one of them (two roads ending at
  // two places of one block left the network in pieces): the one its cheapest join reaches
  const unserved = unservedBlocks(streets, owner, near, pieces, blocks, columns, rows, cell);
  const ringWave = Int32Array.from(wave);
  unserved.forEach((places, k) => { for (const at of places) ringWave[at] = parts + k; });
  const reaching = new Int32Array(unserved.length).fill(-1);
  for (const way of joinedWays(ringWave, parts + unserved.length, middle, boundary, near,
                               columns, rows, cell)) {
    const end = way[way.length - 1], k = ringWave[end] - parts;
    if (k >= 0 && reaching[k] < 0) reaching[k] = end;
  }
  const ends = [];
  reaching.forEach((at, k) => { if (at >= 0) { wave[at] = parts + k; ends.push(at); } });
  for (const way of joinedWays(wave, parts + unserved.length, middle, boundary, near,
                               columns, rows, cell)) {
    for (const at of way) { network[at] = 1; joined[at] = 1; }
  }
  const beside = Math.max(2, Math.round(2 / cell));  // stubs: middles cut at the reach
  for (let at = 0; at < count; at++) {
    if (!middle[at]) continue;
    let cut = false;
    aroundEach(at, columns, rows, next => {
      cut = cut || (boundary[next] && !network[next] && near[next] > reach);
    });
    if (cut && !besideKind(joined, columns, cell, at, 1, beside * cell)) ends.push(at);
  }
  const heads = spaced(ends, columns, cell, 2 * TURNING_HEAD);
  const discs = nearPlaces(heads, columns, rows, cell, TURNING_HEAD - LANE);
  for (let at = 0; at < count; at++) if (discs[at]) network[at] = 1;
  return network;
}
// The ways joining the pieces (``wave``: each seed's piece, 0..parts-1, else -1) into one
// network (see joinedStreets): each way's cells from where two pieces' searches met back
// to a seed of each, not the seed of a middle (the last cell of each: the seed reached,
// the middle's neighbour), the cheapest joins first
function joinedWays(seeds, parts, middle, boundary, near, columns, rows, cell) {
  const count = columns * rows, wave = Int32Array.from(seeds);
  // the search: each place's piece (wave), cost and the place it was reached from;
  // costs in whole units (a step 2 along a boundary, 3 diagonally; ACROSS_PLOTS times
  // that elsewhere), taken from buckets (Dial's); then where two pieces' searches meet,
  // their join: two pieces -> [cost, at, next]
  const clear = (LANE + KERB + SIDEWALK) / cell;
  const open = at => near[at] >= clear || middle[at] === 1;
  const stepTo = (at, next) => (next % columns !== at % columns && Math.abs(next - at) !== 1
    ? 3 : 2) * (boundary[next] ? 1 : ACROSS_PLOTS);
  const cost = new Int32Array(count).fill(-1), from = new Int32Array(count).fill(-1);
  const buckets = [[]];
  for (let at = 0; at < count; at++) if (wave[at] >= 0) { cost[at] = 0; buckets[0].push(at); }
  for (let level = 0; level < buckets.length; level++) {
    for (const at of buckets[level]) {
      if (cost[at] !== level) continue;  // reached cheaper since
      aroundEach(at, columns, rows, next => {
        if (!open(next)) return;
        const reached = level + stepTo(at, next);
        if (cost[next] >= 0 && cost[next] <= reached) return;
        cost[next] = reached; wave[next] = wave[at]; from[next] = at;
        while (buckets.length <= reached) buckets.push([]);
        buckets[reached].push(next);
      });
    }
    buckets[level] = [];
  }
  const joins = new Map();
  for (let at = 0; at < count; at++) {
    if (cost[at] < 0) continue;
    aroundEach(at, columns, rows, next => {
      if (next < at || cost[next] < 0 || wave[next] === wave[at]) return;
      const key = Math.min(wave[at], wave[next]) * parts + Math.max(wave[at], wave[next]);
      const length = cost[at] + stepTo(at, next) + cost[next], known = joins.get(key);
      if (!known || length < known[0]) joins.set(key, [length, at, next]);
    });
  }
  const root = Int32Array.from({length: parts}, (_, id) => id);
  const find = id => { while (root[id] !== id) id = root[id] = root[root[id]]; return id; };
  const sorted = [...joins.entries()].sort((p, q) => p[1][0] - q[1][0] || p[0] - q[0]);
  const ways = [];
  for (const [key, [, at, next]] of sorted) {
    const a = find(Math.floor(key / parts)), b = find(key % parts);
    if (a === b) continue;
    root[Math.max(a, b)] = Math.min(a, b);
    for (const start of [at, next]) {  // back along each search to its piece
      const cells = [];
      for (let way = start; way >= 0 && !middle[way]; way = from[way]) cells.push(way);
      if (cells.length) ways.push(cells);
    }
  }
  return ways;
}
// A drive DRIVE metres wide from the street to each detached house of OUTBUILDING m² or
// more: from the road's place in its plot nearest its walls, straight to them (down the
// distance to the walls, ``near``); a house whose plot no road reaches (its block's
// street runs past a neighbour's plot), from the road's place in its block nearest the
// house's middle, straight to its nearest wall, DRIVE_REACH metres at most. Paved over
// the lawn and the kerb -> the drives' cells
const DRIVE = 2.5, OUTBUILDING = 40, DRIVE_REACH = 100;
function driveCells(kinds, owner, near, pieces, blocks, columns, rows, cell) {
  const {piece, areas} = pieces, {block, detached} = blocks, count = areas.length;
  const house = id => detached[id] && areas[id] * cell * cell >= OUTBUILDING;
  const middleX = new Float64Array(count), middleY = new Float64Array(count);
  const low = new Int32Array(count).fill(rows), high = new Int32Array(count).fill(-1);
  for (let at = 0; at < kinds.length; at++) {
    const id = piece[at], row = Math.floor(at / columns);
    if (!id) continue;
    middleX[id] += at % columns; middleY[id] += row;
    low[id] = Math.min(low[id], row); high[id] = Math.max(high[id], row);
  }
  for (let id = 1; id < count; id++) { middleX[id] /= areas[id]; middleY[id] /= areas[id]; }
  const inBlock = new Map();  // a block -> its houses
  for (let id = 1; id < count; id++) {
    if (house(id)) inBlock.set(block[id], [...(inBlock.get(block[id]) || []), id]);
  }
  const own = new Int32Array(count).fill(-1), fromBlock = new Int32Array(count).fill(-1);
  const best = new Float64Array(count).fill(Infinity);
  for (let at = 0; at < kinds.length; at++) {
    if (kinds[at] !== 3) continue;
    const id = owner[at];
    if (house(id) && (own[id] < 0 || near[at] < near[own[id]])) own[id] = at;
    const column = at % columns, row = (at - column) / columns;
    for (const other of inBlock.get(block[id]) || []) {
      const far = (column - middleX[other]) ** 2 + (row - middleY[other]) ** 2;
      if (far < best[other]) { best[other] = far; fromBlock[other] = at; }
    }
  }
  const way = [];
  for (let id = 1; id < count; id++) {
    let at = own[id];
    for (let steps = 0; at >= 0 && near[at] * cell >= YARD_PATH && steps < 4 * columns; steps++) {
      way.push(at);  // down the distance to the walls: straight to the nearest
      let next = -1;
      aroundEach(at, columns, rows, there => {
        if (near[there] < (next < 0 ? near[at] : near[next])) next = there;
      });
      at = next;
    }
    if (own[id] >= 0 || fromBlock[id] < 0) continue;
    const from = fromBlock[id], fx = from % columns, fy = (from - fx) / columns;
    let wall = -1, closest = Infinity;  // the house's cell nearest the road's place
    for (let at = low[id] * columns; at < (high[id] + 1) * columns; at++) {  // its rows
      if (piece[at] !== id) continue;
      const far = (at % columns - fx) ** 2 + (Math.floor(at / columns) - fy) ** 2;
      if (far < closest) { closest = far; wall = at; }
    }
    const wx = wall % columns, wy = (wall - wx) / columns, length = Math.sqrt(closest);
    if (length * cell > DRIVE_REACH) continue;  // across open land: no drive
    for (let t = 0; t <= length; t += 0.5) {
      way.push(Math.round(fy + (wy - fy) * t / length) * columns
               + Math.round(fx + (wx - fx) * t / length));
    }
  }
  return nearPlaces(way, columns, rows, cell, DRIVE / 2);
}
// What each cell of a grid is, the buildings' cells set in ``building``: 0 building,
// 1 pavement (a path, in a yard), 2 kerb, 3 asphalt, 4 grass; and the distance to the
// nearest building (metres), whether each is street, and whether its pavement is wide
function groundKinds(building, columns, rows, cell) {
  const nearest = new Int32Array(columns * rows);
  const near = distanceField(building, columns, rows, nearest);
  const reached = reachedFromEdge(near, columns, rows, PASSAGE / cell);
  const toStreet = distanceField(reached, columns, rows);
  const kinds = new Uint8Array(columns * rows), street = new Uint8Array(columns * rows);
  const wide = new Uint8Array(columns * rows), garden = new Uint8Array(columns * rows);
  const enclosed = enclosureField(near, columns, rows, cell);
  const {piece, areas} = buildingRows(building, near, columns, rows, cell);
  const owner = nearest.map(at => at < 0 ? 0 : piece[at]);  // each place's plot
  const blocks = plotBlocks(owner, near, areas, columns, rows, cell, enclosed);
  const streets = streetMiddles(owner, near, blocks, columns, rows, cell);
  const network = joinedStreets(streets, owner, near, {piece, areas}, blocks, columns, rows,
                                cell);
  const toMiddle = distanceField(network, columns, rows);
  for (let at = 0; at < columns * rows; at++) {
    if (building[at]) continue;
    const metres = near[at] * cell;
    if (toStreet[at] * cell > PASSAGE + cell) {
      kinds[at] = metres < YARD_PATH ? 1 : 4;
      continue;
    }
    street[at] = 1;
    if (blocks.detached[owner[at]]) {  // a detached house's plot: a garden, or the street
      const road = toMiddle[at] * cell;
      kinds[at] = metres < YARD_PATH ? 1 : road <= LANE ? 3 : road <= LANE + KERB ? 2
        : road <= LANE + KERB + SIDEWALK ? 1 : 4;
      garden[at] = road > LANE + KERB + SIDEWALK ? 1 : 0;
      continue;
    }
    if (metres >= PAVEMENT && metres < WIDE_PAVEMENT + KERB) {
      wide[at] = roomy(near, columns, rows, cell, at) ? 1 : 0;
    }
    const kerb = wide[at] ? WIDE_PAVEMENT : PAVEMENT;
    if (metres < kerb) { kinds[at] = 1; continue; }
    const road = metres <= ROAD_HALF[1];  // past the middle of the widest street: a square
    if (enclosed(at) < (road ? ROAD_ENCLOSED : ENCLOSED)) { kinds[at] = 4; continue; }
    kinds[at] = metres < kerb + KERB ? 2 : road ? 3 : 1;
  }
  kerbLawns(kinds, columns, rows);
  const drives = driveCells(kinds, owner, near, {piece, areas}, blocks, columns, rows, cell);
  for (let at = 0; at < kinds.length; at++) {
    if (!drives[at] || building[at] || kinds[at] === 3) continue;
    kinds[at] = 1; garden[at] = 1;
  }
  return {kinds, near, street, wide, garden, middle: toMiddle};
}
// A kerb where a road meets a lawn (the enclosure turns asphalt to grass across a
// street): the road's cells beside the grass (four neighbours) are kerb, as along a
// pavement; the asphalt ran into the grass with no edge
function kerbLawns(kinds, columns, rows) {
  const edge = [];
  for (let at = 0; at < kinds.length; at++) {
    if (kinds[at] !== 3) continue;
    const column = at % columns;
    if ((column > 0 && kinds[at - 1] === 4) || (column < columns - 1 && kinds[at + 1] === 4)
        || (at >= columns && kinds[at - columns] === 4)
        || (at < (rows - 1) * columns && kinds[at + columns] === 4)) edge.push(at);
  }
  for (const at of edge) kinds[at] = 2;
}
// Cells at least ``every`` metres apart (and from those ``taken``), the first of each
// crowd in the candidates' order (the same each time): a coarse grid of buckets ``every``
// wide keeps the test local
function spaced(candidates, columns, cell, every, taken = []) {
  const buckets = new Map(), chosen = [], span = every / cell;
  for (const at of taken) {  // already placed: kept clear of, not chosen again
    const column = at % columns, row = (at - column) / columns;
    const key = Math.floor(column / span) + ',' + Math.floor(row / span);
    buckets.set(key, [...(buckets.get(key) || []), at]);
  }
  for (const at of candidates) {
    const column = at % columns, row = (at - column) / columns;
    const bx = Math.floor(column / span), by = Math.floor(row / span);
    let clear = true;
    for (let x = bx - 1; x <= bx + 1 && clear; x++) for (let y = by - 1; y <= by + 1; y++) {
      for (const other of buckets.get(x + ',' + y) || []) {
        const otherColumn = other % columns, otherRow = (other - otherColumn) / columns;
        if (Math.hypot(otherColumn - column, otherRow - row) < span) { clear = false; break; }
      }
      if (!clear) break;
    }
    if (!clear) continue;
    chosen.push(at);
    const key = bx + ',' + by;
    buckets.set(key, [...(buckets.get(key) || []), at]);
  }
  return chosen;
}
// The trees, on lawn or in tree pits along streets, never on the paving round a house
// nor in a road: in a pit on a wide pavement TREE_LINE metres (within a cell) from the
// walls, where the street's asphalt lies past its kerb and the pavement runs straight
// for TREE_STRAIGHT metres (a street's, not the ring of paving round a detached house),
// TREE_EVERY apart; and on a street's open lawn (not a yard's: a courtyard, a back
// garden), LAWN_TREE_WALL metres or more from the walls and LAWN_TREE_EDGE from
// anything not grass, LAWN_TREE_EVERY apart, scattered (lawnOrder)
function treeCells(ground, columns, cell) {
  const {kinds, near, wide, street} = ground, rows = kinds.length / columns;
  const pits = [], lawn = [], line = new Uint8Array(kinds.length);
  for (let at = 0; at < kinds.length; at++) {
    line[at] = kinds[at] === 1 && Math.abs(near[at] * cell - TREE_LINE) <= 0.75 * cell ? 1 : 0;
  }
  const pitReach = WIDE_PAVEMENT + KERB - TREE_LINE + cell;
  const reach = Math.max(2, Math.round(TREE_STRAIGHT / 2 / cell));
  const toEdge = distanceField(kinds.map(kind => kind === 4 ? 0 : 1), columns, rows);
  for (let at = 0; at < kinds.length; at++) {
    if (line[at] && wide[at] && besideKind(kinds, columns, cell, at, 3, pitReach)) {
      if (straight(line, columns, rows, at, reach, 0.75 + 0.25 / cell)) pits.push(at);
    } else if (kinds[at] === 4 && street[at] && near[at] * cell - cell / 2 >= LAWN_TREE_WALL
               && toEdge[at] * cell >= LAWN_TREE_EDGE) {
      lawn.push(at);
    }
  }
  const inPits = spaced(pits, columns, cell, TREE_EVERY);
  return inPits.concat(spaced(lawnOrder(lawn), columns, cell, LAWN_TREE_EVERY, inPits));
}
// Places in a scattered order, the same each time (an integer hash of each place): the
// first of each crowd ``spaced`` keeps then lie as a wood's trees do, not on a lattice
function lawnOrder(places) {
  const hash = at => {
    let h = Math.imul(at ^ 0x9e3779b9, 0x85ebca6b);
    h = Math.imul(h ^ (h >>> 13), 0xc2b2ae35);
    return (h ^ (h >>> 16)) >>> 0;
  };
  const keyed = places.map(at => [hash(at), at]);
  keyed.sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  return keyed.map(([, at]) => at);
}
// Whether a dash at ``at`` along ``angle`` stops DASH_STOP metres short of any junction:
// within the street's half width, half a dash and DASH_STOP of it, no ridge cell off its
// line by more than JUNCTION_BAND metres (the middle of a street meeting it) and no place
// farther than ROAD_HALF[1] from the walls (a square or open land it opens into)
const DASH_STOP = 1.5, JUNCTION_BAND = 1.5;
function clearOfJunctions(ground, ridge, columns, rows, cell, at, angle) {
  const {near} = ground, column = at % columns, row = (at - column) / columns;
  const reach = near[at] + (DASH / 2 + DASH_STOP) / cell, band = Math.max(2, JUNCTION_BAND / cell);
  const acrossX = -Math.sin(angle), acrossY = Math.cos(angle), open = ROAD_HALF[1] / cell;
  const r = Math.ceil(reach);
  for (let y = Math.max(0, row - r); y <= Math.min(rows - 1, row + r); y++) {
    for (let x = Math.max(0, column - r); x <= Math.min(columns - 1, column + r); x++) {
      if (Math.hypot(x - column, y - row) > reach) continue;
      const there = y * columns + x;
      if (near[there] > open) return false;
      const off = Math.abs((x - column) * acrossX + (y - row) * acrossY);
      if (ridge[there] && off > band) return false;
    }
  }
  return true;
}
// The cells set in ``mask`` within ``reach`` cells of ``at``: how many, their spread
// (variance, cells²) along and across their principal axis, and the axis' angle
function lineOf(mask, columns, rows, at, reach) {
  const column = at % columns, row = (at - column) / columns;
  let n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (let y = Math.max(0, row - reach); y <= Math.min(rows - 1, row + reach); y++) {
    for (let x = Math.max(0, column - reach); x <= Math.min(columns - 1, column + reach); x++) {
      if (!mask[y * columns + x] || Math.hypot(x - column, y - row) > reach) continue;
      n++; sx += x; sy += y; sxx += x * x; syy += y * y; sxy += x * y;
    }
  }
  if (!n) return {n, along: 0, across: 0, angle: 0, x: column, y: row};
  const cxx = sxx / n - (sx / n) ** 2, cyy = syy / n - (sy / n) ** 2;
  const cxy = sxy / n - (sx / n) * (sy / n);
  const spread = Math.sqrt(((cxx - cyy) / 2) ** 2 + cxy * cxy), mean = (cxx + cyy) / 2;
  return {n, along: mean + spread, across: mean - spread,
          angle: 0.5 * Math.atan2(2 * cxy, cxx - cyy), x: sx / n, y: sy / n};
}
// Whether the cells set in ``mask`` within ``reach`` cells of ``at`` run straight: as
// many as a band along the whole reach holds, none farther than ``off`` cells from
// their principal axis (the ring of paving round a small house curves within it)
function straight(mask, columns, rows, at, reach, off) {
  const {n, angle, x: meanX, y: meanY} = lineOf(mask, columns, rows, at, reach);
  if (n < 1.5 * reach) return false;
  const column = at % columns, row = (at - column) / columns;
  const acrossX = -Math.sin(angle), acrossY = Math.cos(angle);
  for (let y = Math.max(0, row - reach); y <= Math.min(rows - 1, row + reach); y++) {
    for (let x = Math.max(0, column - reach); x <= Math.min(columns - 1, column + reach); x++) {
      if (!mask[y * columns + x] || Math.hypot(x - column, y - row) > reach) continue;
      if (Math.abs((x - meanX) * acrossX + (y - meanY) * acrossY) > off) return false;
    }
  }
  return true;
}
// The road's centre-line dashes: on a street's ridge (the distance to its walls highest
// across it, in one of four directions), ROAD_HALF metres from its walls, DASH_EVERY
// apart, each along the ridge's cells within DASH metres (their principal axis), where
// those lie along a line, stopping short of junctions (clearOfJunctions)
// -> [[cell, along x, along rows], ...]
function dashCells(ground, columns, rows, cell) {
  const {kinds, near, street} = ground, k = 2, ridge = new Uint8Array(kinds.length);
  const candidates = [];
  for (let row = k; row < rows - k; row++) for (let column = k; column < columns - k; column++) {
    const at = row * columns + column, metres = near[at] * cell;
    if (!street[at] || kinds[at] !== 3 || metres < ROAD_HALF[0] || metres > ROAD_HALF[1]) continue;
    for (const [dx, dy] of [[1, 0], [0, 1], [1, 1], [1, -1]]) {
      const a = near[at - dy * k * columns - dx * k], b = near[at + dy * k * columns + dx * k];
      if (near[at] >= a && near[at] >= b && near[at] - (a + b) / 2 >= 0.5 * k) {
        ridge[at] = 1; candidates.push(at); break;
      }
    }
  }
  const dashes = [], reach = Math.round(DASH / cell);
  for (const at of spaced(candidates, columns, cell, DASH_EVERY)) {
    const {n, along, across, angle} = lineOf(ridge, columns, rows, at, reach);
    if (n < reach) continue;  // a speck of ridge, not a street's
    if (across * 6 > along) continue;  // no line: a crossing or a square
    if (!clearOfJunctions(ground, ridge, columns, rows, cell, at, angle)) continue;
    dashes.push([at, Math.cos(angle), Math.sin(angle)]);
  }
  return dashes;
}
// Whether a cell of ``kind`` lies within ``metres`` of the cell at ``at``
function besideKind(kinds, columns, cell, at, kind, metres) {
  const column = at % columns, row = (at - column) / columns, rows = kinds.length / columns;
  const reach = Math.max(1, Math.round(metres / cell));
  for (let y = Math.max(0, row - reach); y <= Math.min(rows - 1, row + reach); y++) {
    for (let x = Math.max(0, column - reach); x <= Math.min(columns - 1, column + reach); x++) {
      if (kinds[y * columns + x] === kind && Math.hypot(x - column, y - row) <= reach) return true;
    }
  }
  return false;
}
// The cells within ``metres`` of any of ``places`` (a mask)
function nearPlaces(places, columns, rows, cell, metres) {
  const mask = new Uint8Array(columns * rows), clear = Math.ceil(metres / cell);
  for (const at of places) {
    const x = at % columns, y = (at - x) / columns;
    for (let r = Math.max(0, y - clear); r <= Math.min(rows - 1, y + clear); r++) {
      for (let c = Math.max(0, x - clear); c <= Math.min(columns - 1, x + clear); c++) {
        if (Math.hypot(c - x, r - y) * cell < metres) mask[r * columns + c] = 1;
      }
    }
  }
  return mask;
}
// The street lamps: cells on a street's pavement LAMP_KERB metres (within half a cell) short
// of its kerb, asphalt beyond it, LAMP_EVERY apart and LAMP_CLEAR from the trees at
// ``trees`` -> [[cell, along x, along rows], ...], the way to the road (the distance to
// the walls growing)
function lampCells(ground, columns, rows, cell, trees = []) {
  const {kinds, near, street, wide, middle, garden} = ground, candidates = [];
  const byTree = nearPlaces(trees, columns, rows, cell, LAMP_CLEAR);
  // along a street between detached houses' blocks the kerb runs LANE + KERB from the
  // street's middle, the pavement outside it: the distance from the middle, falling
  // towards the road; elsewhere the distance from the walls, growing towards it
  const suburb = at => middle[at] * cell < LANE + KERB + SIDEWALK + cell;
  for (let row = 1; row < rows - 1; row++) for (let column = 1; column < columns - 1; column++) {
    const at = row * columns + column;
    if (kinds[at] !== 1 || !street[at] || garden[at] || byTree[at]) continue;
    const [from, line] = suburb(at) ? [middle, LANE + KERB + LAMP_KERB]
      : [near, (wide[at] ? WIDE_PAVEMENT : PAVEMENT) - LAMP_KERB];
    if (Math.abs(from[at] * cell - line) > 0.5 * cell) continue;
    if (!besideKind(kinds, columns, cell, at, 3, LAMP_KERB + KERB + cell)) continue;
    candidates.push(at);
  }
  return spaced(candidates, columns, cell, LAMP_EVERY).map(at => {
    const [from, sign] = suburb(at) ? [middle, -1] : [near, 1];
    const dx = sign * (from[at + 1] - from[at - 1]);
    const dy = sign * (from[at + columns] - from[at - columns]);
    const length = Math.hypot(dx, dy) || 1;
    return [at, dx / length, dy / length];
  });
}
// The benches: on a street's paving (a pavement, the paving round a house) where a lawn
// opens before it, BENCH_EDGE metres (within a cell) short of the grass and facing it,
// the grass going on BENCH_VIEW metres ahead; BENCH_WALL metres or more from the walls,
// no road within BENCH_ROAD metres (not a bus stop's), BENCH_EVERY apart, scattered
// (lawnOrder), BENCH_CLEAR from the trees and lamps (cells) -> [[cell, ahead x, ahead
// rows], ...]
const BENCH_EDGE = 0.6, BENCH_VIEW = 3, BENCH_WALL = 2.5, BENCH_ROAD = 4, BENCH_EVERY = 40;
const BENCH_CLEAR = 2.5;
function benchCells(ground, columns, rows, cell, taken = []) {
  const {kinds, near, street, garden} = ground, candidates = [];
  const toGrass = distanceField(kinds.map(kind => kind === 4 ? 1 : 0), columns, rows);
  const byOthers = nearPlaces(taken, columns, rows, cell, BENCH_CLEAR);
  const facing = at => {
    const dx = toGrass[at - 1] - toGrass[at + 1];
    const dy = toGrass[at - columns] - toGrass[at + columns];
    const length = Math.hypot(dx, dy);
    return length > 1e-6 ? [dx / length, dy / length] : null;
  };
  for (let row = 1; row < rows - 1; row++) for (let column = 1; column < columns - 1; column++) {
    const at = row * columns + column, metres = toGrass[at] * cell;
    if (kinds[at] !== 1 || !street[at] || garden[at] || byOthers[at]) continue;
    if (metres < BENCH_EDGE || metres > BENCH_EDGE + cell) continue;
    if (near[at] * cell < BENCH_WALL) continue;
    if (besideKind(kinds, columns, cell, at, 3, BENCH_ROAD)) continue;
    const ahead = facing(at);
    if (!ahead) continue;
    let open = true;  // grass all the way BENCH_VIEW ahead, past the edge
    for (let metre = metres + cell / 2; metre <= metres + BENCH_VIEW && open; metre += cell) {
      const x = Math.round(column + ahead[0] * metre / cell);
      const y = Math.round(row + ahead[1] * metre / cell);
      open = x >= 0 && x < columns && y >= 0 && y < rows && kinds[y * columns + x] === 4;
    }
    if (open) candidates.push(at);
  }
  return spaced(lawnOrder(candidates), columns, cell, BENCH_EVERY)
    .map(at => [at, ...facing(at)]);
}
"""
