"""Self-contained HTML pages of models: one layout's model with orbit controls beside its
front elevation (``--format html``), or a gallery of every model in a folder
(``facade view``, :mod:`facadecli.viewer.gallery`). Readable in any browser with no
network: three.js r162 (MIT licence) is bundled here from npm and inlined into every page
(see LICENSE-three.txt).

Both pages share one viewer: :data:`VIEWER` sets up three.js in ``#model`` and defines
``show(id)``, which draws the base64 glb held in the script element ``id`` (replacing the
model shown before), frames it, and reports a failure in ``#status``."""

from __future__ import annotations

import base64
import json
from collections.abc import Iterable, Iterator
from functools import cache
from html import escape
from importlib import resources

from facadecli.viewer.ground import GROUND
from facadecli.viewer.landcover import COVER, COVER_DRAWN

THREE_VERSION = "0.162.0"
# specifier -> bundled file
MODULES = {
    "three": "three.module.min.js",
    "three/addons/utils/BufferGeometryUtils.js": "BufferGeometryUtils.js",
    "three/addons/loaders/GLTFLoader.js": "GLTFLoader.js",
    "three/addons/controls/OrbitControls.js": "OrbitControls.js",
    "three/addons/math/SimplexNoise.js": "SimplexNoise.js",
    "three/addons/shaders/CopyShader.js": "CopyShader.js",
    "three/addons/shaders/OutputShader.js": "OutputShader.js",
    "three/addons/shaders/GTAOShader.js": "GTAOShader.js",
    "three/addons/shaders/PoissonDenoiseShader.js": "PoissonDenoiseShader.js",
    "three/addons/postprocessing/Pass.js": "Pass.js",
    "three/addons/postprocessing/MaskPass.js": "MaskPass.js",
    "three/addons/postprocessing/ShaderPass.js": "ShaderPass.js",
    "three/addons/postprocessing/EffectComposer.js": "EffectComposer.js",
    "three/addons/postprocessing/RenderPass.js": "RenderPass.js",
    "three/addons/postprocessing/GTAOPass.js": "GTAOPass.js",
    "three/addons/postprocessing/OutputPass.js": "OutputPass.js",
}
# how the bundled modules import each other ('../shaders/X.js', './X.js'): the files lie
# side by side here, so each relative import is made the bare specifier of its file
RELATIVE = {
    f"'{relative}'": f"'{spec}'"
    for spec in MODULES
    if spec.startswith("three/addons/")
    for relative in (spec.replace("three/addons/", "../"), "./" + spec.rsplit("/", 1)[1])
}


def _module(name: str) -> str:
    text = resources.files(__package__).joinpath(name).read_text(encoding="utf-8")
    for old, new in RELATIVE.items():
        text = text.replace(old, new)
    return "data:text/javascript;base64," + base64.b64encode(text.encode()).decode()


@cache
def import_map() -> str:
    """The import map of the bundled three.js modules, each a data: URL."""
    return json.dumps({"imports": {spec: _module(file) for spec, file in MODULES.items()}})


# The page's title starts "loading: " until the first model is drawn (the browser test
# reads it); a later show() wins over an earlier one still parsing.
VIEWER = """
import * as THREE from 'three';
import {GLTFLoader} from 'three/addons/loaders/GLTFLoader.js';
import {OrbitControls} from 'three/addons/controls/OrbitControls.js';
import {EffectComposer} from 'three/addons/postprocessing/EffectComposer.js';
import {RenderPass} from 'three/addons/postprocessing/RenderPass.js';
import {GTAOPass} from 'three/addons/postprocessing/GTAOPass.js';
import {OutputPass} from 'three/addons/postprocessing/OutputPass.js';
import {SimplexNoise} from 'three/addons/math/SimplexNoise.js';
import {mergeGeometries} from 'three/addons/utils/BufferGeometryUtils.js';
const view = document.getElementById('model');
const status = document.getElementById('status');
// the sky's light is 2.4 times the houses' (below): at 0.55 a sunlit wall is about as light
// as its base colour (#e4d6bd renders as about (223, 207, 181))
const EXPOSURE = 0.55;
const renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
renderer.setPixelRatio(window.devicePixelRatio);
// Khronos PBR Neutral: a colour below its highlights keeps its hue and saturation, and
// highlights roll off to white instead of clipping (ACES filmic, before, drained a pale
// plaster to a near white and shifted every hue)
renderer.toneMapping = THREE.NeutralToneMapping;
renderer.toneMappingExposure = EXPOSURE;
renderer.outputColorSpace = THREE.SRGBColorSpace;
renderer.shadowMap.enabled = true;
renderer.shadowMap.type = THREE.PCFSoftShadowMap;
renderer.shadowMap.autoUpdate = false;  // the scene holds still: drawn again when a model comes
view.appendChild(renderer.domElement);
// The light of a bright day, as a product shot takes it: a sky (blue overhead, pale at
// the horizon, a warm glow round the sun and the sun's disc, fair-weather clouds) over a
// town's skyline and a street, drawn into an equirectangular picture, prefiltered (PMREM)
// into the environment every material is lit by and reflects, and a sun casting soft
// shadows from the same direction as the disc. What glass mirrors is mostly this
// picture's horizon band (a pane seen from the front or a street mirrors the skyline, the
// street and the sky just over them), so the band is drawn as a street sees it: distant
// houses in the haze of their distance (aerial perspective); below the horizon the fronts
// of the houses across the street, then pale sunlit paving, both fading into the
// horizon's haze; not a dark floor, which made every pane a flat dark slate. The
// backdrop behind the model is the same sky, drawn finer and without the skyline and
// street (the model's own ground stands there), its horizon the haze the ground fades
// into. Seeded: the same pictures every time.
// mulberry32: a seeded stream of numbers in [0, 1), the same for the same seed
function seeded(seed) {
  return () => {
    seed = (seed + 0x6D2B79F5) | 0;
    let t = Math.imul(seed ^ (seed >>> 15), 1 | seed);
    t = (t + Math.imul(t ^ (t >>> 7), 61 | t)) ^ t;
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}
// The sky is brighter than the houses and paving it lights (in daylight several times
// brighter than a wall in shade): what glass mirrors of it stands out as it does in a photo.
const SKY_LIGHT = 2.4;
const sunDirection = new THREE.Vector3(-0.45, 0.72, 0.53).normalize();  // front left, 46 degrees up
const ZENITH = new THREE.Color(0x6f98cf), HORIZON = new THREE.Color(0xe4ebf2);
const SUN_DISC = Math.cos(0.6 * Math.PI / 180);  // the disc's half-angle, a little wide
// Clouds: seeded value noise in several octaves, laid on a plane above the
// eye (so they shrink and crowd towards the horizon, and fade out into its haze), about a
// quarter of the sky (CLOUD_COVER sets it), lit towards the sun and greyer where thick.
const CLOUD_GRID = 256, CLOUD_COVER = 0.42, CLOUD_SCALE = 1.8, CLOUD_CONTRAST = 2.2;
const cloudLattice = (() => {
  const random = seeded(23), values = new Float32Array(CLOUD_GRID * CLOUD_GRID);
  for (let i = 0; i < values.length; i++) values[i] = random();
  return values;
})();
function valueNoise(x, y) {
  const fx = Math.floor(x), fy = Math.floor(y), tx = x - fx, ty = y - fy;
  const sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  const x0 = fx & (CLOUD_GRID - 1), y0 = fy & (CLOUD_GRID - 1);
  const x1 = (x0 + 1) & (CLOUD_GRID - 1), y1 = (y0 + 1) & (CLOUD_GRID - 1);
  const at = (column, row) => cloudLattice[row * CLOUD_GRID + column];
  const top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * sx;
  const bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * sx;
  return top + (bottom - top) * sy;
}
function cloudiness(direction) {  // 0 (clear) .. 1 (thick cloud) in a direction above the horizon
  const y = direction.y;
  if (y <= 0.01) return 0;
  const x = direction.x / y * CLOUD_SCALE, z = direction.z / y * CLOUD_SCALE;
  let sum = 0, weight = 0.5, frequency = 1;
  for (let octave = 0; octave < 5; octave++) {
    sum += weight * valueNoise(x * frequency + 17.3 * octave, z * frequency - 9.1 * octave);
    weight *= 0.5; frequency *= 2.03;
  }
  const spread = (sum / 0.97 - 0.5) * CLOUD_CONTRAST + 0.5;  // the octaves' sum is narrow
  const density = THREE.MathUtils.smoothstep(spread, 1 - CLOUD_COVER, 1 - CLOUD_COVER + 0.22);
  return density * THREE.MathUtils.smoothstep(y, 0.03, 0.25);  // lost in the haze low down
}
// The sky's radiance in a direction (linear, before the white balance): the gradient,
// the clouds, the glow round the sun and its disc. ``colour`` receives it.
// a little cool: the white balance (below) warms the whole sky as it cancels its blue
const CLOUD_TOP = new THREE.Color(0xeef3ff), CLOUD_BASE = new THREE.Color(0xa9b4c6);
const GLOW = new THREE.Color(0xfff1dc);
function cloudShade(direction, cloud, shade) {  // a cloud's colour, lit from the sun's side
  const lit = 0.9 + 0.3 * Math.max(0, direction.dot(sunDirection));
  return shade.copy(CLOUD_BASE).lerp(CLOUD_TOP, 1 - cloud * 0.6)
    .multiplyScalar(SKY_LIGHT * 1.35 * lit);
}
function skyRadiance(direction, colour, clouds = true) {
  const y = Math.max(direction.y, 0);
  colour.copy(HORIZON).lerp(ZENITH, Math.pow(y, 0.6)).multiplyScalar(SKY_LIGHT);
  const cloud = clouds ? cloudiness(direction) : 0;
  if (cloud > 0) colour.lerp(cloudShade(direction, cloud, new THREE.Color()), cloud);
  const towards = Math.max(0, direction.dot(sunDirection));
  colour.add(GLOW.clone().multiplyScalar(2.5 * Math.pow(towards, 24)));
  if (towards > SUN_DISC) colour.add(GLOW.clone().multiplyScalar(40));
  return colour;
}
// An equirectangular picture (row 0 straight down) of the sky above and, below the
// horizon, the horizon's haze as ``below(y, colour)`` changes it (y: the direction's
// height, -1..0); with ``skyline``, the distant houses of the horizon band too.
// Below the horizon the street: the fronts of the houses across it down to FRONTS (the
// sine of their foot's angle below the eye), sunlit (SUNLIT times a far house's light),
// their windows WINDOWS as bright, then paving. What a pane seen from the front or 35°
// mirrors is here, 5-15° below the horizon: it was paving as bright as the haze, the
// same grey all over, so a pane showed nothing but a dark slate.
const FRONTS = 0.26, WINDOWS = 0.5, SUNLIT = 2;
function skyPicture(width, height, below, skyline, clouds = true) {
  const data = new Float32Array(width * height * 4);
  const direction = new THREE.Vector3(), colour = new THREE.Color(), house = new THREE.Color();
  const horizon = HORIZON.clone().multiplyScalar(SKY_LIGHT);
  for (let row = 0; row < height; row++) {
    const elevation = ((row + 0.5) / height - 0.5) * Math.PI, y = Math.sin(elevation);
    let block = 0;
    for (let column = 0; column < width; column++) {
      const u = (column + 0.5) / width, azimuth = (u - 0.5) * 2 * Math.PI;
      direction.set(Math.cos(azimuth) * Math.cos(elevation), y,  // as three reads it
                    Math.sin(azimuth) * Math.cos(elevation));
      if (skyline) while (skyline[block][1] <= u) block++;
      if (y >= 0) {
        skyRadiance(direction, colour, clouds);
        if (skyline) {
          const [, , top, tone, light] = skyline[block];
          if (y < top) {  // a house far off: lit by the sky, half lost in the haze
            house.copy(tone).multiplyScalar(light);
            colour.copy(horizon).lerp(house, 0.85 - 3 * y);
          }
        }
      } else {
        below(y, colour.copy(horizon));
        if (skyline && y > -FRONTS) {  // the houses across the street, their windows darker
          const [from, to, , tone, light] = skyline[block];
          const across = (u - from) / (to - from), storey = (-y / FRONTS * 3) % 1;
          const glazed = across > 0.2 && across < 0.8 && storey > 0.25 && storey < 0.75;
          house.copy(tone).multiplyScalar(SUNLIT * light * (glazed ? WINDOWS : 1));
          colour.lerp(house, 0.7 * Math.min(1, -y / 0.03));  // in the haze at the horizon
        }
      }
      const at = (row * width + column) * 4;
      data[at] = colour.r; data[at + 1] = colour.g; data[at + 2] = colour.b; data[at + 3] = 1;
    }
  }
  return data;
}
// White balance: the light a wall takes from the environment, whichever way it faces
// (each direction weighted by its solid angle and by the cosine a vertical wall sees it
// at), is grey at its own luminance; the blue overhead and the warm paving and glow
// cancel, so a wall of a known colour renders as that colour, in sun (the sun is white)
// or in shade. The gains, one a channel, found on the environment's picture, apply to
// the backdrop as well: what is seen and what lights are one sky.
function whiteBalance(data, width, height) {
  const mean = [0, 0, 0];
  for (let row = 0; row < height; row++) {
    const weight = Math.cos(((row + 0.5) / height - 0.5) * Math.PI) ** 2;
    for (let column = 0; column < width; column++) {
      const at = (row * width + column) * 4;
      for (let channel = 0; channel < 3; channel++) mean[channel] += weight * data[at + channel];
    }
  }
  const luminance = 0.2126 * mean[0] + 0.7152 * mean[1] + 0.0722 * mean[2];
  return mean.map(sum => luminance / sum);
}
function balanced(data, gains) {
  for (let at = 0; at < data.length; at += 4) {
    for (let channel = 0; channel < 3; channel++) data[at + channel] *= gains[channel];
  }
  return data;
}
function equirectangular(data, width, height) {
  const picture = new THREE.DataTexture(data, width, height, THREE.RGBAFormat, THREE.FloatType);
  picture.mapping = THREE.EquirectangularReflectionMapping;
  picture.flipY = false;
  picture.magFilter = THREE.LinearFilter;
  picture.needsUpdate = true;
  return picture;
}
// -> the environment (PMREM), the backdrop's picture and the haze (the backdrop's colour
// at the horizon, which the fog fades the ground into)
function sky() {
  const paving = new THREE.Color(0xb3ada3);
  const houses = [0xd8cfc2, 0xc9b8a4, 0xe4dfd6, 0xb9a48f, 0xcfd3d6].map(c => new THREE.Color(c));
  const random = seeded(7);  // the skyline's houses, the same each time
  const skyline = [];  // [from, to) of the azimuth (0..1), the top (sine of its angle), tone
  for (let at = 0; at < 1;) {
    const wide = 0.006 + 0.018 * random();
    skyline.push([at, at + wide, 0.015 + 0.07 * random() * random(), houses[(random() * 5) | 0],
                  0.55 + 0.3 * random()]);
    at += wide;
  }
  // the street: the far paving in the horizon's haze, sunlit paving nearer
  const street = (y, colour) => colour.lerp(paving, Math.min(1, Math.pow(-y * 3, 0.7)));
  const width = 1024, height = 512;
  const lighting = skyPicture(width, height, street, skyline);
  const gains = whiteBalance(lighting, width, height);
  const picture = equirectangular(balanced(lighting, gains), width, height);
  const prefilter = new THREE.PMREMGenerator(renderer);
  const environment = prefilter.fromEquirectangular(picture).texture;
  prefilter.dispose(); picture.dispose();
  // the backdrop: 0.18 degrees a texel, about three pixels of a 900-pixel view
  const haze = HORIZON.clone().multiplyScalar(SKY_LIGHT);
  haze.setRGB(haze.r * gains[0], haze.g * gains[1], haze.b * gains[2]);
  const backdrop = equirectangular(
    balanced(skyPicture(1024, 512, () => {}, null, false), gains), 1024, 512);  // haze below
  const clouds = equirectangular(balanced(cloudPicture(2048, 1024), gains), 2048, 1024);
  return {environment, backdrop, clouds, haze};
}
// The backdrop's clouds apart from its clear sky, an equirectangular picture as
// skyPicture's: each cloud's colour and, as alpha, how thick it is (0 clear), so the
// backdrop lays them over the sky at elevations of their own (placeBackdrop)
function cloudPicture(width, height) {
  const data = new Float32Array(width * height * 4);
  const direction = new THREE.Vector3(), shade = new THREE.Color();
  for (let row = height / 2; row < height; row++) {
    const elevation = ((row + 0.5) / height - 0.5) * Math.PI, y = Math.sin(elevation);
    for (let column = 0; column < width; column++) {
      const azimuth = ((column + 0.5) / width - 0.5) * 2 * Math.PI;
      direction.set(Math.cos(azimuth) * Math.cos(elevation), y,
                    Math.sin(azimuth) * Math.cos(elevation));
      const cloud = cloudiness(direction);
      if (cloud <= 0) continue;
      cloudShade(direction, cloud, shade);
      const at = (row * width + column) * 4;
      data[at] = shade.r; data[at + 1] = shade.g; data[at + 2] = shade.b; data[at + 3] = cloud;
    }
  }
  return data;
}
const scene = new THREE.Scene();
const daylight = sky();
scene.environment = daylight.environment;
// The backdrop: the sky's picture on a dome round the eye, drawn before the scene (a scene
// of its own, out of the ambient occlusion's depth). Its horizon is where the ground is
// lost in the haze (fog.far away): at eye level for an eye on the street, below it for an
// eye high over a district, which at 30-35 degrees up looks down at its picture's top.
// Above that horizon the sky's gradient, its elevations stretched up to SKY_STRETCH times
// as the horizon drops, so the top of such a picture is sky (pale at the haze, bluer
// above), where it was the haze below the sky's horizon. The clouds are not stretched
// (three times flatter, they read as streaks over a district): over a lowered horizon
// they are those up to CLOUD_LIFT radians higher in the sky, as an eye over the town
// sees them, fading in over CLOUD_FADE radians above the haze.
const SKY_STRETCH = 3, CLOUD_LIFT = 0.25, CLOUD_FADE = 0.08;
let lowHorizon = false;  // a district seen from above (light); a façade's is at eye level
const backdrop = new THREE.Scene();
const dome = new THREE.Mesh(new THREE.SphereGeometry(1, 64, 32), new THREE.ShaderMaterial({
  uniforms: {sky: {value: daylight.backdrop}, clouds: {value: daylight.clouds},
             horizon: {value: 0}, stretch: {value: 1}, lift: {value: 0}},
  vertexShader: `varying vec3 vDirection;
    void main() {
      vDirection = position;
      gl_Position = (projectionMatrix * modelViewMatrix * vec4(position, 1.0)).xyww;
    }`,
  fragmentShader: `uniform sampler2D sky, clouds; uniform float horizon, stretch, lift;
    varying vec3 vDirection;
    #include <common>
    vec2 equirectangular(float around, float up) {
      return vec2(around, clamp(up, -0.5 * PI, 0.5 * PI) * RECIPROCAL_PI + 0.5);
    }
    void main() {
      vec3 d = normalize(vDirection);
      float above = asin(clamp(d.y, -1.0, 1.0)) - horizon;
      float around = atan(d.z, d.x) * RECIPROCAL_PI2 + 0.5;
      vec3 colour = texture2D(sky, equirectangular(around, above * stretch)).rgb;
      vec4 cloud = texture2D(clouds, equirectangular(around, above + lift));
      float fade = lift > 0.0 ? smoothstep(0.0, ${CLOUD_FADE.toFixed(2)}, above) : 1.0;
      gl_FragColor = vec4(mix(colour, cloud.rgb, cloud.a * fade), 1.0);
      #include <tonemapping_fragment>
      #include <colorspace_fragment>
    }`,
  side: THREE.BackSide, depthTest: false, depthWrite: false}));
dome.frustumCulled = false;
backdrop.add(dome);
// the dome round the camera, its horizon where the ground (at ground.position) fades out
function placeBackdrop() {
  dome.position.copy(camera.position);
  dome.scale.setScalar((camera.near + camera.far) / 2);
  dome.updateMatrixWorld();
  const high = Math.max(camera.position.y - ground.position.y, 0);
  const horizon = !lowHorizon ? 0
    : -Math.asin(Math.min(1, high / Math.max(scene.fog.far, 1e-6)));
  dome.material.uniforms.horizon.value = horizon;
  const lowered = THREE.MathUtils.smoothstep(-horizon, 0.01, 0.1);
  dome.material.uniforms.stretch.value = 1 + (SKY_STRETCH - 1) * lowered;
  dome.material.uniforms.lift.value = CLOUD_LIFT * lowered;
}
// placed by frame(): the model clear, the ground fading out into the horizon's haze
scene.fog = new THREE.Fog(daylight.haze, 1, 2);
const sun = new THREE.DirectionalLight(0xffffff, 3.4);  // white, as the sky's light is
sun.castShadow = true;
sun.shadow.bias = -0.0002;
scene.add(sun, sun.target);
// The paving: square slabs of a mid grey stone (an albedo of about a fifth, as concrete
// paving has), a little lighter or darker each (seeded), with darker joints, so the ground
// reads as paving at street level instead of a blown-out white under the bright sky.
const SLAB = 0.6;  // metres a side
function pavingPicture() {
  const slabs = 4, cell = 32, size = slabs * cell, data = new Uint8Array(size * size * 4);
  const random = seeded(11);
  const tones = Array.from({length: slabs * slabs}, () => 0.92 + 0.16 * random());
  for (let y = 0; y < size; y++) for (let x = 0; x < size; x++) {
    const joint = x % cell === 0 || y % cell === 0;
    const tone = joint ? 0.62 : tones[((y / cell) | 0) * slabs + ((x / cell) | 0)]
      * (0.97 + 0.06 * random());
    const at = (y * size + x) * 4;
    data[at] = 134 * tone; data[at + 1] = 127 * tone; data[at + 2] = 116 * tone;
    data[at + 3] = 255;
  }
  const picture = new THREE.DataTexture(data, size, size);
  picture.colorSpace = THREE.SRGBColorSpace;
  picture.wrapS = picture.wrapT = THREE.RepeatWrapping;
  picture.magFilter = THREE.LinearFilter;
  picture.minFilter = THREE.LinearMipmapLinearFilter;
  picture.generateMipmaps = true;
  picture.anisotropy = renderer.capabilities.getMaxAnisotropy();
  picture.needsUpdate = true;
  return picture;
}
const paving = pavingPicture();
const ground = new THREE.Mesh(  // takes the shadows; large enough to reach the haze
  new THREE.CircleGeometry(1, 64).rotateX(-Math.PI / 2),
  new THREE.MeshStandardMaterial({map: paving, roughness: 0.9}));
ground.receiveShadow = true;
ground.visible = false;
scene.add(ground);
// A district's ground reads as a town's (facadecli.viewer.ground's GROUND): streets where
// its open ground reaches the town round it (a pavement along the walls, a kerb, asphalt,
// the land round the district a street too, to the haze), a path and grass in the yards
// the streets do not reach, street trees on the wide pavements and dashes down the middle
// of the streets. A picture of the plan's cells and a margin round it says how much of
// each a place is (red paving, green asphalt, blue grass, alpha the kerb), and the
// ground's shader mixes them; a façade's is all paving.
// Past the plan's margin the land round the district is, within TOWN_PAVED metres, what
// most of the district's open ground is (``town``: paving, or grass for a town of lawns),
// and the ground fades into the horizon's haze from ``hazeFrom`` metres from the eye to
// the fog's far end (light), so no edge or band shows where the plan ends.
const TOWN_PAVED = 20, TOWN_EDGE = 6;
const PAVED = new THREE.Vector4(1, 0, 0, 0), LAWNS = new THREE.Vector4(0, 0, 1, 0);
const uses = {regions: {value: null}, regionsFrom: {value: new THREE.Vector2(0, 0)},
              regionsSize: {value: new THREE.Vector2(1, 1)}, town: {value: PAVED.clone()},
              hazeFrom: {value: 1}};
function regionsPicture(data, columns, rows) {
  const picture = new THREE.DataTexture(data, columns, rows);
  picture.magFilter = picture.minFilter = THREE.LinearFilter;
  picture.needsUpdate = true;
  return picture;
}
// A lawn's edge, soft and ragged (a verge, not a line ruled at the plan's cell): its
// share of grass the mean of four places LAWN_BLUR metres round, each moved by a smooth
// noise up to LAWN_WOBBLE metres, eased; and the grass's tone, smooth noise at two
// scales (blades and patches), not squares of 0.2 m, which drew a staircase along every
// lawn's edge. The same at a place each time.
const LAWN_BLUR = 0.5, LAWN_WOBBLE = 0.45;
const LAWN_EDGE = `
  float lawnHash(vec2 p) { return fract(sin(dot(p, vec2(12.9898, 78.233))) * 43758.5453); }
  float lawnNoise(vec2 p) {
    vec2 i = floor(p), f = fract(p);
    f = f * f * (3.0 - 2.0 * f);
    return mix(mix(lawnHash(i), lawnHash(i + vec2(1.0, 0.0)), f.x),
               mix(lawnHash(i + vec2(0.0, 1.0)), lawnHash(i + vec2(1.0, 1.0)), f.x), f.y);
  }
  float lawnAt(vec2 place) { return texture2D(regions, (place - regionsFrom) / regionsSize).b; }
  float lawnEdge(vec2 place) {
    vec2 moved = place + ${(2 * LAWN_WOBBLE).toFixed(2)} * (vec2(
      lawnNoise(place * 1.3), lawnNoise(place * 1.3 + 17.0)) - 0.5);
    float blur = ${LAWN_BLUR.toFixed(2)};
    float share = 0.25 * (lawnAt(moved + vec2(blur, 0.0)) + lawnAt(moved - vec2(blur, 0.0))
                          + lawnAt(moved + vec2(0.0, blur)) + lawnAt(moved - vec2(0.0, blur)));
    return smoothstep(0.15, 0.85, share);
  }
  float lawnTone(vec2 place) {
    return 0.72 + 0.32 * lawnNoise(place * 7.0) + 0.24 * lawnNoise(place * 0.35);
  }`;
const allPaving = () => regionsPicture(new Uint8Array([255, 0, 0, 0]), 1, 1);
uses.regions.value = allPaving();
ground.material.onBeforeCompile = shader => {
  Object.assign(shader.uniforms, uses);
  shader.vertexShader = 'varying vec2 vGround;\\n' + shader.vertexShader.replace(
    '#include <begin_vertex>',
    '#include <begin_vertex>\\nvGround = (modelMatrix * vec4(position, 1.0)).xz;');
  shader.fragmentShader = `uniform sampler2D regions; uniform vec2 regionsFrom, regionsSize;
    uniform vec4 town; uniform float hazeFrom;
    #define TOWN_PAVED ${TOWN_PAVED.toFixed(1)}
    #define TOWN_EDGE ${TOWN_EDGE.toFixed(1)}
    varying vec2 vGround;
    ${LAWN_EDGE}\\n` + shader.fragmentShader.replace('#include <map_fragment>', `
    #include <map_fragment>
    vec2 inPlan = (vGround - regionsFrom) / regionsSize;
    vec4 share = texture2D(regions, inPlan);
    share.b = lawnEdge(vGround);
    // past the plan's margin the town's streets give way to what most of the district's
    // open ground is (its squares, or its lawns), out to the haze
    // (from TOWN_EDGE metres inside the margin's edge: the picture's edge, clamped, drew
    // streaks past it)
    vec2 past = (inPlan - clamp(inPlan, 0.0, 1.0)) * regionsSize;
    vec2 inside = min(inPlan, 1.0 - inPlan) * abs(regionsSize);
    float beyond = length(past) > 0.0 ? length(past) : -min(inside.x, inside.y);
    share = mix(share, town, smoothstep(-TOWN_EDGE, TOWN_PAVED, beyond));
    float speck = fract(sin(dot(floor(vGround * 5.0), vec2(12.9898, 78.233))) * 43758.5453);
    vec3 asphalt = vec3(0.042, 0.042, 0.045) * (0.9 + 0.2 * speck);
    vec3 grass = vec3(0.05, 0.075, 0.028) * lawnTone(vGround);
    vec3 paved = diffuseColor.rgb * mix(1.0, 1.5, share.a);
    diffuseColor.rgb = (paved * share.r + asphalt * share.g + grass * share.b)
      / max(share.r + share.g + share.b, 1e-3);`);
};
ground.material.customProgramCacheKey = () => 'ground-regions';
{
  const regions = ground.material.onBeforeCompile;
  ground.material.onBeforeCompile = shader => {  // the ground fades into the haze
    regions(shader);
    shader.fragmentShader = shader.fragmentShader.replace('#include <fog_fragment>', `
      #include <fog_fragment>
      #ifdef USE_FOG
      float hazed = clamp((vFogDepth - hazeFrom) / max(fogFar - hazeFrom, 1e-3), 0.0, 1.0);
      gl_FragColor.rgb = mix(gl_FragColor.rgb, fogColor, hazed * hazed);
      #endif`);
  };
}
// The ground and what stands on it end where the haze has swallowed them (fog.far away),
// so the sky's backdrop, its horizon there (placeBackdrop), shows over them
function endsInHaze(material, more = shader => shader) {
  material.onBeforeCompile = shader => {
    more(shader);
    shader.fragmentShader = shader.fragmentShader.replace('#include <fog_fragment>',
      '#include <fog_fragment>\\n#ifdef USE_FOG\\nif (vFogDepth > fogFar) discard;\\n#endif');
  };
}
endsInHaze(ground.material, ground.material.onBeforeCompile);
// What stands on a district's ground (trees, dashes, lamps, benches) fades into the haze
// as the ground under it does: with the fog alone, the trees on a lawn far off stood
// out of the hazed ground as pale ghosts over the horizon
function fadesWithGround(material) {
  endsInHaze(material, shader => {
    shader.uniforms.hazeFrom = uses.hazeFrom;
    shader.fragmentShader = 'uniform float hazeFrom;\\n' + shader.fragmentShader.replace(
      '#include <fog_fragment>', `#include <fog_fragment>
      #ifdef USE_FOG
      float hazed = clamp((vFogDepth - hazeFrom) / max(fogFar - hazeFrom, 1e-3), 0.0, 1.0);
      gl_FragColor.rgb = mix(gl_FragColor.rgb, fogColor, hazed * hazed);
      #endif`);
  });
  material.customProgramCacheKey = () => 'fades-with-ground';
}
// The street trees (a trunk and a crown, each one instanced mesh: two draw calls whatever
// their number), the centre-line dashes and the street lamps (one more each), seeded: the
// same each time
const TREE_TRUNK = 2.6;
// A street lamp of painted steel, LAMP_HIGH metres, one mesh (one draw call for them all):
// a tapering pole, an arm reaching LAMP_ARM metres over the road (+x), a flat lantern
const LAMP_HIGH = 5.6, LAMP_ARM = 1.1;
function lampShape() {
  const pole = new THREE.CylinderGeometry(0.05, 0.08, LAMP_HIGH, 8).translate(0, LAMP_HIGH / 2, 0);
  const arm = new THREE.BoxGeometry(LAMP_ARM, 0.06, 0.06)
    .translate(LAMP_ARM / 2, LAMP_HIGH - 0.05, 0);
  const lantern = new THREE.BoxGeometry(0.55, 0.12, 0.26)
    .translate(LAMP_ARM - 0.05, LAMP_HIGH - 0.12, 0);
  return mergeGeometries([pole, arm, lantern].map(part => part.toNonIndexed()));
}
const trees = {
  trunks: new THREE.InstancedMesh(
    new THREE.CylinderGeometry(0.12, 0.17, TREE_TRUNK, 7).translate(0, TREE_TRUNK / 2, 0),
    new THREE.MeshStandardMaterial({color: 0x4a3a2c, roughness: 0.95}), 1),
  crowns: new THREE.InstancedMesh(
    new THREE.IcosahedronGeometry(1, 1),
    new THREE.MeshStandardMaterial({color: 0xffffff, roughness: 0.9, flatShading: true}), 1),
  dashes: new THREE.InstancedMesh(
    new THREE.PlaneGeometry(1, 1).rotateX(-Math.PI / 2),
    new THREE.MeshStandardMaterial({color: 0xd8d6cc, roughness: 0.8, polygonOffset: true,
                                    polygonOffsetFactor: -2, polygonOffsetUnits: -2}), 1),
  lamps: new THREE.InstancedMesh(lampShape(), new THREE.MeshStandardMaterial(
    {color: 0x3b3f42, roughness: 0.55, metalness: 0.6}), 1),
};
for (const part of Object.values(trees)) {
  fadesWithGround(part.material);
  part.count = 0; part.frustumCulled = false; part.receiveShadow = true;
  scene.add(part);
}
trees.trunks.castShadow = trees.crowns.castShadow = trees.lamps.castShadow = true;
const CROWN_GREENS = [0x3f5e2a, 0x4d6b30, 0x35522a, 0x56703a].map(c => new THREE.Color(c));
function placeStreetParts(cells, dashes, lamps, place) {
  const random = seeded(13), matrix = new THREE.Matrix4(), turn = new THREE.Quaternion();
  const up = new THREE.Vector3(0, 1, 0), size = new THREE.Vector3(), at = new THREE.Vector3();
  const grow = (mesh, count) => {
    if (mesh.instanceMatrix.count >= count) return mesh;
    const bigger = new THREE.InstancedMesh(mesh.geometry, mesh.material, count);
    bigger.castShadow = mesh.castShadow; bigger.receiveShadow = true;
    bigger.frustumCulled = false;
    scene.remove(mesh); mesh.dispose(); scene.add(bigger);
    return bigger;
  };
  trees.trunks = grow(trees.trunks, cells.length);
  trees.crowns = grow(trees.crowns, cells.length);
  trees.dashes = grow(trees.dashes, dashes.length);
  trees.lamps = grow(trees.lamps, lamps.length);
  cells.forEach((cell, index) => {
    const [x, y, z] = place(cell);
    const radius = 1.5 + 0.6 * random(), tall = 1.1 + 0.35 * random();
    const height = 0.85 + 0.3 * random();
    turn.setFromAxisAngle(up, random() * 2 * Math.PI);
    matrix.compose(at.set(x, y, z), turn, size.set(1, height, 1));
    trees.trunks.setMatrixAt(index, matrix);
    matrix.compose(at.set(x, y + TREE_TRUNK * height + radius * tall * 0.7, z), turn,
                   size.set(radius, radius * tall, radius));
    trees.crowns.setMatrixAt(index, matrix);
    trees.crowns.setColorAt(index, CROWN_GREENS[(random() * CROWN_GREENS.length) | 0]);
  });
  dashes.forEach(([cell, across, down], index) => {
    const [x, y, z] = place(cell);
    turn.setFromAxisAngle(up, Math.atan2(down, across));  // rows run to -z
    matrix.compose(at.set(x, y, z), turn, size.set(DASH, 1, 0.12));
    trees.dashes.setMatrixAt(index, matrix);
  });
  lamps.forEach(([cell, across, down], index) => {
    const [x, y, z] = place(cell);
    turn.setFromAxisAngle(up, Math.atan2(down, across));  // the arm over the road
    matrix.compose(at.set(x, y, z), turn, size.set(1, 1, 1));
    trees.lamps.setMatrixAt(index, matrix);
  });
  trees.trunks.count = trees.crowns.count = cells.length;
  trees.dashes.count = dashes.length;
  trees.lamps.count = lamps.length;
  for (const part of Object.values(trees)) {
    part.instanceMatrix.needsUpdate = true;
    if (part.instanceColor) part.instanceColor.needsUpdate = true;
  }
}
// The benches (street furniture, one instanced mesh: one draw call whatever their
// number, no randomness): a seat of timber slats BENCH_SEAT metres up on two cast-iron
// ends, a back rest leaning back; the seat's front faces +x, the way benchCells gives
const BENCH_LONG = 1.8, BENCH_SEAT = 0.45;
function benchShape() {
  const slat = (deep, high, x, y, lean = 0) => new THREE.BoxGeometry(deep, high, BENCH_LONG)
    .rotateZ(lean).translate(x, y, 0);
  const parts = [slat(0.14, 0.04, 0.13, BENCH_SEAT), slat(0.14, 0.04, -0.02, BENCH_SEAT),
                 slat(0.04, 0.14, -0.14, BENCH_SEAT + 0.2, 0.2),
                 slat(0.04, 0.14, -0.17, BENCH_SEAT + 0.38, 0.2)];
  const timber = mergeGeometries(parts.map(part => part.toNonIndexed()));
  const ends = [-1, 1].map(side => new THREE.BoxGeometry(0.42, BENCH_SEAT, 0.06)
    .translate(0.02, BENCH_SEAT / 2, side * (BENCH_LONG / 2 - 0.15)).toNonIndexed());
  const iron = mergeGeometries(ends);
  // one mesh, two materials (groups): timber, then the iron ends
  return mergeGeometries([timber, iron], true);
}
let benches = new THREE.InstancedMesh(benchShape(), [
  new THREE.MeshStandardMaterial({color: 0x8a6240, roughness: 0.8}),
  new THREE.MeshStandardMaterial({color: 0x2b2e2f, roughness: 0.5, metalness: 0.6})], 1);
for (const material of benches.material) fadesWithGround(material);
benches.count = 0; benches.frustumCulled = false;
benches.castShadow = benches.receiveShadow = true;
scene.add(benches);
function placeBenches(cells, place) {
  if (benches.instanceMatrix.count < cells.length) {  // grown: a mesh with room for them
    const bigger = new THREE.InstancedMesh(benches.geometry, benches.material, cells.length);
    bigger.frustumCulled = false; bigger.castShadow = bigger.receiveShadow = true;
    scene.remove(benches); benches.dispose(); scene.add(bigger);
    benches = bigger;
  }
  const matrix = new THREE.Matrix4(), turn = new THREE.Quaternion();
  const up = new THREE.Vector3(0, 1, 0), at = new THREE.Vector3();
  const size = new THREE.Vector3(1, 1, 1);
  cells.forEach(([cell, across, down], index) => {
    const [x, y, z] = place(cell);
    turn.setFromAxisAngle(up, Math.atan2(down, across));  // rows run to -z, as the lamps
    benches.setMatrixAt(index, matrix.compose(at.set(x, y, z), turn, size));
  });
  benches.count = cells.length;
  benches.instanceMatrix.needsUpdate = true;
}
function groundRegions(model, box, district) {  // a model after another: its own ground
  uses.regions.value.dispose();
  uses.regions.value = allPaving();
  uses.town.value.copy(PAVED);
  delete document.body.dataset.ground;
  placeStreetParts([], [], [], null);
  placeBenches([], null);
  placeLandCover([], 0);  // the land cover mapped (facadecli.viewer.landcover)
  delete document.body.dataset.cover;
  const buildings = model.children.length;
  if (!district || buildings < 2 || buildings > 65535) return;  // its plan, as a street's
  const {cell, columns, rows, building} = districtPlan(model, box);
  const margin = Math.ceil(GROUND_MARGIN / cell);  // the town round the district
  const wide = columns + 2 * margin, deep = rows + 2 * margin;
  const built = new Uint8Array(wide * deep);
  for (let row = 0; row < rows; row++) for (let column = 0; column < columns; column++) {
    if (building[row * columns + column]) built[(row + margin) * wide + column + margin] = 1;
  }
  const plan = groundKinds(built, wide, deep, cell);
  const data = new Uint8Array(wide * deep * 4), counts = [0, 0, 0, 0];
  const channel = [0, 0, 3, 1, 2];  // building (as paving), pavement, kerb, asphalt, grass
  for (let row = 0; row < deep; row++) for (let column = 0; column < wide; column++) {
    const at = row * wide + column, kind = plan.kinds[at];
    data[at * 4 + channel[kind]] = 255;
    if (kind === 2) data[at * 4] = 255;  // a kerb is paving, lighter
    if (kind && row >= margin && row < margin + rows && column >= margin
        && column < margin + columns) counts[kind - 1]++;  // within the plan
  }
  const share = count => Math.round(count / (columns * rows) * 1000) / 1000;
  const x = column => box.min.x + (column - margin + 0.5) * cell;
  const z = row => box.min.z + (rows + margin - row - 0.5) * cell;
  const place = at => [x(at % wide), box.min.y, z(Math.floor(at / wide))];
  const covered = coverPlan(plan, box.min.x - margin * cell, box.min.z + (rows + margin) * cell,
                            wide, deep, cell);  // what OSM maps there: the rules fill the rest
  const treesAt = treeCells(plan, wide, cell).filter(covered.open);
  const dashes = dashCells(plan, wide, deep, cell).filter(([at]) => covered.open(at));
  const lamps = lampCells(plan, wide, deep, cell, treesAt).filter(([at]) => covered.open(at));
  const trees = [...treesAt, ...covered.trees.map((_, k) => -1 - k)];  // theirs below 0
  placeStreetParts(trees, dashes, lamps, at => at >= 0 ? place(at)
    : [covered.trees[-1 - at][0], box.min.y, covered.trees[-1 - at][1]]);
  const benchesAt = benchCells(plan, wide, deep, cell, [...treesAt, ...lamps.map(([at]) => at)])
    .filter(([at]) => covered.open(at));
  placeBenches(benchesAt, place);
  placeLandCover(covered.polygons, box.min.y);
  document.body.dataset.cover = JSON.stringify(coverCounts(covered, wide, margin, rows, columns));
  document.body.dataset.ground = JSON.stringify({
    paving: share(counts[0]), kerb: share(counts[1]), asphalt: share(counts[2]),
    grass: share(counts[3]), cell, area: +(columns * rows * cell * cell).toFixed(1),
    trees: treesAt.map(at => place(at).map(v => +v.toFixed(2))),
    dashes: dashes.length, lamps: lamps.map(([at]) => place(at).map(v => +v.toFixed(2))),
    benches: benchesAt.map(([at]) => place(at).map(v => +v.toFixed(2)))});
  uses.regions.value.dispose();
  uses.regions.value = regionsPicture(data, wide, deep);
  // the picture's row 0 is the plan's, at the district's +z edge (districtPlan)
  uses.regionsFrom.value.set(box.min.x - margin * cell, box.min.z + (rows + margin) * cell);
  uses.regionsSize.value.set(wide * cell, -deep * cell);
  uses.town.value.copy(counts[3] > counts[0] + counts[2] ? LAWNS : PAVED);
}
const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 5000);
const controls = new OrbitControls(camera, renderer.domElement);
// Ambient occlusion (GTAO) between the scene's render and the output pass (tone mapping and
// sRGB); WebGL 1 draws without it. Its noise is seeded, so a picture is the same each time.
class SteadyGTAOPass extends GTAOPass {
  generateNoise(size = 64) {
    const random = seeded(1);
    const simplex = new SimplexNoise({random});
    const data = new Uint8Array(size * size * 4);
    for (let i = 0; i < size; i++) for (let j = 0; j < size; j++) {
      const at = (i * size + j) * 4;
      data[at] = (simplex.noise(i, j) * 0.5 + 0.5) * 255;
      data[at + 1] = (simplex.noise(i + size, j) * 0.5 + 0.5) * 255;
      data[at + 2] = (simplex.noise(i, j + size) * 0.5 + 0.5) * 255;
      data[at + 3] = (simplex.noise(i + size, j + size) * 0.5 + 0.5) * 255;
    }
    const noise = new THREE.DataTexture(data, size, size);
    noise.wrapS = noise.wrapT = THREE.RepeatWrapping;
    noise.needsUpdate = true;
    return noise;
  }
}
let composer = null, occlusion = null;
if (renderer.capabilities.isWebGL2) {
  const target = new THREE.WebGLRenderTarget(1, 1, {type: THREE.HalfFloatType, samples: 4});
  composer = new EffectComposer(renderer, target);
  composer.addPass(new RenderPass(backdrop, camera));
  const drawn = new RenderPass(scene, camera);
  drawn.clear = false;  // over the backdrop (which writes no depth)
  composer.addPass(drawn);
  occlusion = new SteadyGTAOPass(scene, camera, 1, 1);
  occlusion.updateGtaoMaterial({samples: 16, distanceExponent: 1, thickness: 1, scale: 1});
  occlusion.updatePdMaterial(
    {lumaPhi: 10, depthPhi: 2, normalPhi: 3, radius: 6, rings: 2, samples: 16});
  occlusion.blendIntensity = 0.85;
  // normals from the depth buffer: glTF without normals (drawn flat) has none to give
  for (const material of [occlusion.gtaoMaterial, occlusion.pdMaterial]) {
    material.defines.NORMAL_VECTOR_TYPE = 0;
  }
  composer.addPass(occlusion);
  composer.addPass(new OutputPass());
}
let drawing = false;  // one drawing per frame, only when something changed
function redraw() {
  if (drawing) return;
  drawing = true;
  requestAnimationFrame(() => {
    drawing = false;
    controls.update();
    placeBackdrop();
    if (composer) { composer.render(); return; }
    renderer.render(backdrop, camera);
    renderer.autoClear = false;
    renderer.render(scene, camera);
    renderer.autoClear = true;
  });
}
controls.addEventListener('change', redraw);
function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h); camera.aspect = w / h; camera.updateProjectionMatrix();
  if (composer) { composer.setPixelRatio(window.devicePixelRatio); composer.setSize(w, h); }
  redraw();
}
let shown = null, asked = 0, moved = false;  // moved: turned by the user since framed
controls.addEventListener('start', () => { moved = true; });
window.addEventListener('resize', () => { resize(); if (shown && !moved) frame(shown); });
function bytesOf(id) {
  const text = atob(document.getElementById(id).textContent);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  return bytes;
}
function dispose(object) {
  object.traverse(part => {
    if (part.geometry) part.geometry.dispose();
    const materials = Array.isArray(part.material) ? part.material : [part.material];
    for (const material of materials) {
      if (!material) continue;
      for (const value of Object.values(material)) if (value && value.isTexture) value.dispose();
      material.dispose();
    }
  });
}
// Everything opaque casts and takes shadows; glass lets light by. Glass (a material with
// KHR_materials_transmission) is drawn by its transmission alone: its alpha is the glb's
// fallback for viewers without the extension, and blending by it too would dim the pane's
// reflection to a third (a dark pane) and count what lies behind it twice.
const isGlass = material => material.transmission > 0;
// A window's glass is a sealed unit of two panes, four faces that each reflect about 4%
// (float glass, ior 1.52): seen square on it reflects about 15% of what lies before it, not
// the 4% of one face, which left every pane a dark slate. The glb keeps its glass's ior;
// the viewer scales its F0 colour to the unit's reflectance.
const GLAZING_REFLECTANCE = 0.15;
const fresnelAtNormal = ior => ((ior - 1) / (ior + 1)) ** 2;
const materialsOf = part => Array.isArray(part.material) ? part.material : [part.material];
function castsShadows(model) {
  model.traverse(part => {
    if (!part.isMesh) return;
    const materials = materialsOf(part);
    part.castShadow = materials.every(m => !m.transparent && !isGlass(m));
    part.receiveShadow = true;
    for (const material of materials.filter(isGlass)) {
      material.transparent = false; material.opacity = 1; material.depthWrite = true;
      material.specularColor.setScalar(GLAZING_REFLECTANCE / fresnelAtNormal(material.ior));
    }
  });
}
// ?view=ANGLE,ELEVATION,ZOOM,X,Y,Z: seen from ANGLE degrees around and ELEVATION up, ZOOM
// times closer than the fit, looking at the point X, Y, Z (0..1 across the model's box,
// its width, height and depth; without them, the fit's aim); ?view=street,ANGLE: at eye
// height, ANGLE degrees round, the whole model in view (a district: in one of its
// streets, fitDistrictStreet); ?bare: the model alone
const query = new URLSearchParams(location.search);
const wantedView = (query.get('view') || '').split(',');
const street = wantedView[0] === 'street';
if (street) wantedView.shift();
const [around, up, zoom, atX, atY, atZ] = wantedView.map(parseFloat);
const or = (value, fallback) => Number.isFinite(value) ? value : fallback;
if (query.has('bare')) document.body.classList.add('bare');
function corners(box) {
  const {min, max} = box;
  return [0, 1, 2, 3, 4, 5, 6, 7].map(i => new THREE.Vector3(
    i & 1 ? max.x : min.x, i & 2 ? max.y : min.y, i & 4 ? max.z : min.z));
}
// Framing: the view's half-angles as tangents, an 8% margin inside the picture's edges
const MARGIN = 1.08;
function halfTangents() {
  const tanV = Math.tan(camera.fov * Math.PI / 360) / MARGIN;
  return [tanV * camera.aspect, tanV];
}
// The camera looking along -seen (seen: from the model towards the camera) that holds the
// points (corners of boxes, see bounds) in the view and stands as close as that allows:
// each side of the view is a plane every point must lie inside, which bounds the camera's
// place across, up and back linearly (an exact fit, not a sphere's). The points' picture
// is centred and fills the view along its tighter axis. Returns the point the camera aims
// at (where its axis passes the centre's depth), the camera's distance from it, the
// distance at which the points' picture would fill the view's height (high), and whether
// it does (filled; else its width binds, and the view has room above and below it).
// headroom: the share of the view's height kept clear at its top (a district seen from
// above: the sky over its horizon, see light)
function fitBox(points, centre, seen, headroom = 0) {
  const [tanH, tanV] = halfTangents();
  const tanTop = tanV * (1 - 2 * headroom);
  const forward = seen.clone().negate();
  const right = forward.clone().cross(new THREE.Vector3(0, 1, 0)).normalize();
  const upward = right.clone().cross(forward);
  let rightmost = -Infinity, leftmost = -Infinity, top = -Infinity, bottom = -Infinity;
  const offset = new THREE.Vector3();
  for (const point of points) {  // a loop, not Math.max(...): a city has many points
    offset.subVectors(point, centre);
    const x = offset.dot(right), y = offset.dot(upward), z = offset.dot(forward);
    rightmost = Math.max(rightmost, x - tanH * z); leftmost = Math.max(leftmost, -x - tanH * z);
    top = Math.max(top, y - tanTop * z); bottom = Math.max(bottom, -y - tanV * z);
  }
  const wide = (rightmost + leftmost) / (2 * tanH), high = (top + bottom) / (tanTop + tanV);
  const distance = Math.max(wide, high, 0.01);
  const aim = centre.clone().addScaledVector(right, (rightmost - leftmost) / 2)
    .addScaledVector(upward, (top - bottom + (tanV - tanTop) * distance) / 2);
  return {aim, distance, high: Math.max(high, 0.01), filled: high >= wide};
}
// A person's eye above the ground, for the street-level view
const EYE = 1.6;
// Street level: the camera at eye height above the box's foot, looking ANGLE degrees round
// from the front, tilted up (or down) just enough, and as close as the whole box allows:
// for each tilt the box's corners bound how far back the camera must stand (linearly, as
// in fitBox, with its height fixed); of the tilts that let it stand within 1% of the
// closest, the one that centres the box's picture up and down (when its width binds,
// many tilts do nearly as well). The whole façade is seen, its upper windows included,
// however low and wide it is.
function fitStreet(box, centre, angle) {
  const [tanH, tanV] = halfTangents();
  const a = angle * Math.PI / 180;
  const level = new THREE.Vector3(-Math.sin(a), 0, -Math.cos(a));  // looking, level
  const right = level.clone().cross(new THREE.Vector3(0, 1, 0)).normalize();
  const base = new THREE.Vector3(centre.x, box.min.y + EYE, centre.z);
  const offsets = corners(box).map(corner => corner.sub(base));
  const steepest = Math.atan(tanV) * 0.98;  // past it the eye's own foot is out of view
  const tilts = [];
  for (let step = -60; step <= 60; step++) {
    const tilt = steepest * step / 60, cos = Math.cos(tilt), sin = Math.sin(tilt);
    const forward = level.clone().multiplyScalar(cos).add(new THREE.Vector3(0, sin, 0));
    const upward = right.clone().cross(forward);
    let back = 0, rightmost = -Infinity, leftmost = Infinity;
    for (const o of offsets) {
      const x = o.dot(right), y = o.dot(upward), z = o.dot(forward);
      back = Math.max(back, (y - tanV * z) / (sin + tanV * cos),
                      (-y - tanV * z) / (tanV * cos - sin));
      rightmost = Math.max(rightmost, x - tanH * z);
      leftmost = Math.min(leftmost, x + tanH * z);
    }
    back = Math.max(back, (rightmost - leftmost) / (2 * tanH * cos));
    const across = (rightmost + leftmost) / 2;
    let high = -Infinity, low = Infinity;  // the box's picture, up and down (tangents)
    for (const o of offsets) {
      const seen = o.clone().addScaledVector(level, back).addScaledVector(right, -across);
      const y = seen.dot(upward) / Math.max(seen.dot(forward), 1e-9);
      high = Math.max(high, y); low = Math.min(low, y);
    }
    tilts.push({back, forward, across, off: Math.abs(high + low)});
  }
  const closest = Math.min(...tilts.map(tilt => tilt.back));
  const best = tilts.filter(tilt => tilt.back <= 1.01 * closest)
    .reduce((best, tilt) => tilt.off < best.off ? tilt : best);
  const position = base.clone().addScaledVector(level, -best.back)
    .addScaledVector(right, best.across);
  const distance = Math.max(centre.clone().sub(position).dot(best.forward), 0.01);
  return {position, aim: position.clone().addScaledVector(best.forward, distance), distance};
}
// Street level in a district (a model of several buildings, wider and deeper than tall):
// the eye EYE metres up in its open space, where the nearest buildings fill the view. The
// district's plan is drawn from above (each building, a child of the model, in a colour of
// its own: which stands highest in each cell of about PLAN_CELL metres, and how high), and
// the cells of walls with openings marked: those with a corner of a pane of glass within
// OPENING_REACH metres (a pane's corners, read from the model's meshes, lie in its wall's
// reveal, inside the building's cells, which seen from above hide the pane). A spot is open
// where nothing stands and no building is nearer than CLEARANCE; rays from each open spot
// of a lattice every STREET_STEP metres, RAYS round, find the first building each way, and
// whether the wall they meet has openings. Of every spot and heading, the view that holds
// the most of buildings' façades wins (viewScore): the sum over the buildings seen of the
// square root of the share of the picture each fills (a street of houses, near and far,
// beats one wall close up: eight houses a sixteenth of the picture each score 2), a blank
// wall's share counted BLANK_WALL of a windowed one's (a street of windows beats one of
// blank brick), a wall by the share of its height in the picture (cut off at the top, it
// counts less), a wall d metres away, nearer than STAND_BACK, d / STAND_BACK of its share
// (4 m from a house, the picture holds its ground floor alone), and a building filling
// more than FILL_MOST of the picture counted less the more it fills, nothing when it fills
// it alone (the eye stands back from a house until others join it); ties keep the first
// (the same view each time).
const PLAN_CELL = 0.25, PLAN_CELLS = 768, CLEARANCE = 4, STREET_STEP = 2, RAYS = 144;
const STREET_TILT = 6;  // degrees the street camera looks up: more of the houses, less paving
const STREET_SPOTS = 4096, STREET_REACH = 150;  // the search's bounds (see fitDistrictStreet)
const OPENING_REACH = 1, BLANK_WALL = 0.2, STAND_BACK = 10, FILL_MOST = 0.25;
// the most corners of panes read for the plan's openings (past it every k-th one): the
// work is bounded whatever the district's size
const OPENING_CORNERS = 1 << 21;
// The plan's cells (indices as districtPlan's) with a corner of glass within OPENING_REACH
// metres: each glass mesh's vertices (each instance's, for a mesh drawn as GPU instances)
// in the world, then a square dilation, across and down.
function planOpenings(model, box, cell, columns, rows) {
  const meshes = [];
  let corners = 0;
  model.traverse(part => {
    if (!part.isMesh || !materialsOf(part).some(isGlass)) return;
    const position = part.geometry.attributes.position;
    if (!position) return;
    meshes.push(part);
    corners += position.count * (part.isInstancedMesh ? part.count : 1);
  });
  const stride = Math.max(1, Math.ceil(corners / OPENING_CORNERS));
  const marked = new Uint8Array(columns * rows);
  const corner = new THREE.Vector3(), instance = new THREE.Matrix4(), world = new THREE.Matrix4();
  let visited = 0;
  model.updateMatrixWorld(true);
  for (const part of meshes) {
    const position = part.geometry.attributes.position;
    const copies = part.isInstancedMesh ? part.count : 1;
    for (let copy = 0; copy < copies; copy++) {
      world.copy(part.matrixWorld);
      if (part.isInstancedMesh) {
        part.getMatrixAt(copy, instance);
        world.multiply(instance);
      }
      for (let vertex = 0; vertex < position.count; vertex++, visited++) {
        if (visited % stride) continue;
        corner.fromBufferAttribute(position, vertex).applyMatrix4(world);
        const column = Math.floor((corner.x - box.min.x) / cell);
        const row = Math.floor((box.min.z + rows * cell - corner.z) / cell);
        if (column >= 0 && column < columns && row >= 0 && row < rows) {
          marked[row * columns + column] = 1;
        }
      }
    }
  }
  const reach = Math.max(1, Math.round(OPENING_REACH / cell));
  const across = new Uint8Array(columns * rows), openings = new Uint8Array(columns * rows);
  for (let row = 0; row < rows; row++) spread(marked, across, row * columns, 1, columns, reach);
  for (let column = 0; column < columns; column++) {
    spread(across, openings, column, columns, rows, reach);
  }
  return openings;
}
// One line of a square dilation: each of ``count`` cells of ``to`` (from ``start``, every
// ``step``) set where ``from`` has a cell set within ``reach`` cells of it along the line.
function spread(from, to, start, step, count, reach) {
  for (let i = 0, last = -Infinity; i < count; i++) {  // the last set cell
    if (from[start + i * step]) last = i;
    to[start + i * step] = i - last <= reach ? 1 : 0;
  }
  for (let i = count - 1, next = Infinity; i >= 0; i--) {
    if (from[start + i * step]) next = i;
    if (next - i <= reach) to[start + i * step] = 1;
  }
}
function districtPlan(model, box) {
  const size = box.getSize(new THREE.Vector3());
  const cell = Math.max(PLAN_CELL, Math.max(size.x, size.z) / PLAN_CELLS);
  const columns = Math.max(1, Math.ceil(size.x / cell));
  const rows = Math.max(1, Math.ceil(size.z / cell));
  const high = Math.max(box.max.y - box.min.y, 0.01);
  const swapped = [];
  model.children.forEach((building, index) => {
    const material = new THREE.ShaderMaterial({
      uniforms: {id: {value: index + 1}, low: {value: box.min.y}, high: {value: high}},
      vertexShader: `uniform float low, high; varying float height;
        void main() {
          vec4 world = vec4(position, 1.0);
          #ifdef USE_INSTANCING
            world = instanceMatrix * world;
          #endif
          world = modelMatrix * world;
          height = clamp((world.y - low) / high, 0.0, 1.0);
          gl_Position = projectionMatrix * viewMatrix * world;
        }`,
      fragmentShader: `uniform float id; varying float height;
        void main() {
          gl_FragColor = vec4(floor(id / 256.0) / 255.0, mod(id, 256.0) / 255.0, height, 1.0);
        }`,
      side: THREE.DoubleSide,
    });
    building.traverse(part => {
      if (part.isMesh) { swapped.push([part, part.material]); part.material = material; }
    });
  });
  const above = new THREE.OrthographicCamera(
    -columns * cell / 2, columns * cell / 2, rows * cell / 2, -rows * cell / 2,
    0.5, high + 1.5);
  above.up.set(0, 0, -1);  // the picture's right is +x, its top -z: row 0 (the bottom) +z
  const middle = new THREE.Vector3(box.min.x + columns * cell / 2, 0,
                                   box.min.z + rows * cell / 2);
  above.position.set(middle.x, box.max.y + 1, middle.z);
  above.lookAt(middle.x, box.min.y, middle.z);
  above.updateMatrixWorld(); above.updateProjectionMatrix();
  const target = new THREE.WebGLRenderTarget(columns, rows);
  const pixels = new Uint8Array(columns * rows * 4);
  const planScene = new THREE.Scene(), parent = model.parent;
  planScene.add(model);
  const clear = renderer.getClearColor(new THREE.Color()), alpha = renderer.getClearAlpha();
  renderer.setClearColor(0x000000, 0);
  renderer.setRenderTarget(target);
  renderer.clear();
  renderer.render(planScene, above);
  renderer.readRenderTargetPixels(target, 0, 0, columns, rows, pixels);
  renderer.setRenderTarget(null);
  renderer.setClearColor(clear, alpha);
  planScene.remove(model);
  if (parent) parent.add(model);
  for (const [part, material] of swapped) { part.material.dispose(); part.material = material; }
  target.dispose();
  const building = new Int32Array(columns * rows), height = new Float32Array(columns * rows);
  for (let at = 0; at < columns * rows; at++) {
    if (pixels[at * 4 + 3] === 0) continue;
    building[at] = pixels[at * 4] * 256 + pixels[at * 4 + 1];
    height[at] = pixels[at * 4 + 2] / 255 * high;
  }
  const near = distanceField(building, columns, rows);  // in cells, Euclidean
  const openings = planOpenings(model, box, cell, columns, rows);
  return {cell, columns, rows, building, height, near, openings,
          x: column => box.min.x + (column + 0.5) * cell,
          z: row => box.min.z + rows * cell - (row + 0.5) * cell};
}
// What a building adds to a street view's score: the square root of the share of the
// picture it fills as counted (its blank walls BLANK_WALL of its windowed ones, its walls
// nearer than STAND_BACK less), falling from FILL_MOST of the picture (as it fills it) to
// nothing when it fills it alone
function viewScore(share, counted) {
  const score = Math.sqrt(counted);
  return share <= FILL_MOST ? score : score * Math.max(0, 1 - share) / (1 - FILL_MOST);
}
function fitDistrictStreet(model, box) {
  const buildings = model.children.length;
  if (buildings < 2 || buildings > 65535) return null;  // its plan tells 65,535 apart
  const plan = districtPlan(model, box);
  const {cell, columns, rows, building, height, near, openings} = plan;
  const [tanH, tanV] = halfTangents();
  const halfH = Math.atan(tanH * MARGIN), halfV = Math.atan(tanV * MARGIN);
  const tilt = STREET_TILT * Math.PI / 180;
  const span = Math.max(1, Math.round(halfH / (2 * Math.PI / RAYS)));  // rays each side
  // the work is bounded whatever the district's size: at most STREET_SPOTS spots (a wider
  // lattice in a large city), each ray STREET_REACH metres at most
  const reach = Math.min(Math.hypot(columns, rows), STREET_REACH / cell);
  const step = Math.max(1, Math.round(STREET_STEP / cell),
                        Math.ceil(Math.sqrt(columns * rows / STREET_SPOTS)));
  const hitBuilding = new Int32Array(RAYS), hitFill = new Float32Array(RAYS);
  const hitCounted = new Float32Array(RAYS), hitOpen = new Uint8Array(RAYS);
  let best = null;
  for (let row = step >> 1; row < rows; row += step) {
    for (let column = step >> 1; column < columns; column += step) {
      if (near[row * columns + column] * cell < CLEARANCE) continue;
      for (let ray = 0; ray < RAYS; ray++) {  // the first building along each ray
        const a = ray * 2 * Math.PI / RAYS, dx = Math.sin(a), dy = Math.cos(a);  // rows: north
        hitBuilding[ray] = 0; hitFill[ray] = 0; hitCounted[ray] = 0; hitOpen[ray] = 0;
        for (let t = 1; t < reach; t += 0.5) {
          const x = Math.floor(column + 0.5 + dx * t), y = Math.floor(row + 0.5 + dy * t);
          if (x < 0 || x >= columns || y < 0 || y >= rows) break;
          const at = y * columns + x;
          if (!building[at]) continue;
          const distance = t * cell;  // the share of the view's height the building fills
          const top = Math.atan2(height[at] - EYE, distance), foot = -Math.atan2(EYE, distance);
          const shown = Math.min(top, tilt + halfV) - Math.max(foot, tilt - halfV);
          hitBuilding[ray] = building[at]; hitFill[ray] = Math.max(0, shown) / (2 * halfV);
          hitOpen[ray] = openings[at];
          // what of it counts: the share of its height in view (a house cut off at the
          // picture's top counts less), less for a wall nearer than STAND_BACK, and less
          // for a blank wall
          hitCounted[ray] = hitFill[ray] * Math.max(0, shown) / (top - foot)
            * Math.min(1, distance / STAND_BACK) * (openings[at] ? 1 : BLANK_WALL);
          break;
        }
      }
      for (let heading = 0; heading < RAYS; heading++) {
        // building -> the share of the picture it fills, what of that counts, and the
        // share of its walls with openings
        const shares = new Map();
        for (let k = -span; k <= span; k++) {
          const ray = (heading + k + RAYS) % RAYS;
          if (!hitBuilding[ray]) continue;
          const seen = shares.get(hitBuilding[ray]) || [0, 0, 0];
          seen[0] += hitFill[ray] / (2 * span + 1); seen[1] += hitCounted[ray] / (2 * span + 1);
          if (hitOpen[ray]) seen[2] += hitFill[ray] / (2 * span + 1);
          shares.set(hitBuilding[ray], seen);
        }
        let score = 0;
        for (const [share, counted] of shares.values()) score += viewScore(share, counted);
        if (!best || score > best.score + 1e-9) {
          best = {score, column, row, heading, shares};
        }
      }
    }
  }
  if (!best) return null;
  const a = best.heading * 2 * Math.PI / RAYS;  // ray 0 looks north (-z), then clockwise
  const forward = new THREE.Vector3(Math.sin(a) * Math.cos(tilt), Math.sin(tilt),
                                    -Math.cos(a) * Math.cos(tilt));
  const position = new THREE.Vector3(plan.x(best.column), box.min.y + EYE, plan.z(best.row));
  const distance = 20;
  const named = building => building.userData.name || building.name;  // as the glb names it
  const ids = [...best.shares.keys()].sort((p, q) => p - q);
  const seen = ids.map(id => named(model.children[id - 1]));
  // each building's share of the picture, and the share of its walls with openings
  const shares = ids.map(id => +best.shares.get(id)[0].toFixed(4));
  const open = ids.map(id => +best.shares.get(id)[2].toFixed(4));
  document.body.dataset.street = JSON.stringify({
    eye: position.toArray().map(v => +v.toFixed(3)), heading: +(a * 180 / Math.PI).toFixed(1),
    seen, shares, open});
  return {position, aim: position.clone().addScaledVector(forward, distance), distance};
}
// The sun's shadow camera fitted round the model's box, seen from the sun, so a facade and a
// district both get shadows as sharp as the map allows.
function fitSun(box, centre, radius) {
  sun.position.copy(centre).addScaledVector(sunDirection, 2 * radius);
  sun.target.position.copy(centre);
  const right = new THREE.Vector3(0, 1, 0).cross(sunDirection).normalize();
  const upward = sunDirection.clone().cross(right);
  const shadow = sun.shadow.camera;
  shadow.left = shadow.bottom = Infinity; shadow.right = shadow.top = -Infinity;
  for (const corner of corners(box)) {
    const offset = corner.sub(centre);
    const x = offset.dot(right), y = offset.dot(upward);
    shadow.left = Math.min(shadow.left, x); shadow.right = Math.max(shadow.right, x);
    shadow.bottom = Math.min(shadow.bottom, y); shadow.top = Math.max(shadow.top, y);
  }
  const extent = Math.max(shadow.right - shadow.left, shadow.top - shadow.bottom);
  const size = extent > 60 ? 4096 : 2048;
  shadow.left -= extent / 50; shadow.right += extent / 50;
  shadow.bottom -= extent / 50; shadow.top += extent / 50;
  shadow.near = radius / 2;
  shadow.far = 3 * radius + (box.max.y - box.min.y) / sunDirection.y;
  shadow.updateProjectionMatrix();
  if (sun.shadow.mapSize.x !== size) {
    sun.shadow.mapSize.set(size, size);
    if (sun.shadow.map) { sun.shadow.map.dispose(); sun.shadow.map = null; }
  }
  sun.shadow.normalBias = 1.5 * extent / size;
  renderer.shadowMap.needsUpdate = true;
}
const SEEN_FROM = 35;  // degrees round from the front, unless ?view says otherwise
const DISTRICT_RISE = 30;  // degrees up a district is seen from (a façade from 8.5)
const SKY_BAND = 0.1;  // of a district's picture seen from above: sky at its top
// What the camera frames (points): a model's box's eight corners; a district's, those of
// each of its buildings' boxes (up to FRAMED_BUILDINGS of them), which hug the buildings
// (the district's box has corners in the air over low houses, and framing those left the
// whole district too small, or cut a building at the picture's edge when brought closer)
const FRAMED_BUILDINGS = 20000;
function bounds(model) {
  const box = new THREE.Box3().setFromObject(model);
  if (box.isEmpty()) box.setFromCenterAndSize(new THREE.Vector3(), new THREE.Vector3(10, 10, 10));
  const size = box.getSize(new THREE.Vector3());
  // wider and deeper than tall, or with the land cover of a city round it
  const district = Math.min(size.x, size.z) > 2 * size.y || Boolean(landCover);
  let points = corners(box);
  if (district && model.children.length <= FRAMED_BUILDINGS) {
    points = [];
    for (const building of model.children) {
      const own = new THREE.Box3().setFromObject(building);
      if (!own.isEmpty()) points.push(...corners(own));
    }
    if (!points.length) points = corners(box);
  }
  return {box, size, centre: box.getCenter(new THREE.Vector3()), district, points,
          radius: Math.max(size.length() / 2, 0.01), rise: district ? DISTRICT_RISE : 8.5};
}
function direction(angle, rise) {
  const a = angle * Math.PI / 180, r = rise * Math.PI / 180;
  return new THREE.Vector3(Math.sin(a) * Math.cos(r), Math.sin(r), Math.cos(a) * Math.cos(r));
}
// The corners (x, z) of the box round the land cover mapped (none without it)
function coverCorners() {
  const polygons = landCover ? coverPolygons(landCover) : [];
  if (!polygons.length) return [];
  let west = Infinity, east = -Infinity, north = Infinity, south = -Infinity;
  for (const {rings} of polygons) for (const [x, z] of rings[0]) {
    west = Math.min(west, x); east = Math.max(east, x);
    north = Math.min(north, z); south = Math.max(south, z);
  }
  return [[west, north], [east, north], [west, south], [east, south]];
}
// The ground, the haze, the sun's shadows and the ambient occlusion's reach, fitted to the
// model as first framed (not to where the camera is turned: a picture is the same each time)
function light(model) {
  const {box, centre, radius, rise, points, district} = bounds(model);
  groundRegions(model, box, district);
  const fit = fitBox(points, centre, direction(SEEN_FROM, rise)).distance;
  const haze = fit + 2 * radius;
  scene.fog.near = haze; scene.fog.far = 4 * haze;
  // a district seen from so high that the picture's top edge looks down at the ground
  // (from 30° up, 10° down): the ground lost in the haze SKY_BAND of the picture's height
  // under its top, so the top is sky over the haze's horizon (placeBackdrop), not ground
  // to the frame; but not short of the district's far corners (its buildings stand on
  // their streets, clear of the haze, the sky over them)
  const topEdge = (or(up, rise) - camera.fov / 2) * Math.PI / 180;
  lowHorizon = district && topEdge > 0;
  let clearTo = 0;  // seen from above: the depth the ground stays clear to
  if (lowHorizon) {
    const seen = direction(or(around, SEEN_FROM), or(up, rise));
    const framed = fitBox(points, centre, seen, SKY_BAND);
    const eyeAt = framed.aim.clone().addScaledVector(seen, framed.distance);
    const eye = eyeAt.y - box.min.y;
    const fov = camera.fov * Math.PI / 180, fade = topEdge + SKY_BAND * fov;
    const depth = eye / Math.sin(fade) * Math.cos(fov / 2 - SKY_BAND * fov);
    let farthest = 0;  // the depth of the district's farthest corner on the ground
    for (const corner of corners(box)) {
      if (corner.y !== box.min.y) continue;
      farthest = Math.max(farthest, eyeAt.clone().sub(corner).dot(seen));
    }
    scene.fog.far = Math.min(scene.fog.far, Math.max(depth, 1.1 * farthest));
    // the land round the buildings stays clear out to the scene's far edge (its mapped
    // land cover's too; within the picture), the haze beyond it: fading from the
    // district's middle hid a wood or a river 40 m past the buildings
    let extent = farthest;
    for (const [x, z] of coverCorners()) {
      extent = Math.max(extent, eyeAt.clone().sub(new THREE.Vector3(x, box.min.y, z)).dot(seen));
    }
    extent = Math.min(extent, scene.fog.far);
    scene.fog.near = Math.min(scene.fog.near, Math.max(0.6 * scene.fog.far, 0.9 * extent));
    clearTo = Math.min(scene.fog.near, extent);
    model.traverse(part => {
      if (part.isMesh) for (const material of materialsOf(part)) material.fog = false;
    });
  }
  // a district's ground fades from the distance of its middle, or seen from above from
  // its far edge (clearTo): a façade's in the fog alone
  uses.hazeFrom.value = district ? Math.min(scene.fog.near, Math.max(fit, clearTo))
    : scene.fog.far;
  ground.position.set(centre.x, box.min.y - radius * 1e-4, centre.z);
  ground.scale.setScalar(4 * haze);
  // the circle's texture coordinates span its diameter: slabs SLAB metres a side
  paving.repeat.setScalar(8 * haze / (4 * SLAB));
  ground.visible = true;
  fitSun(box, centre, radius);
  // AO reaches about as far as a window's reveal on a facade, a yard in a district
  if (occlusion) occlusion.updateGtaoMaterial({radius: Math.max(0.3, fit / 60)});
  redraw();
}
// A district seen from ?view=ANGLE with no elevation: from the lowest elevation, from
// DISTRICT_LOWEST up to DISTRICT_HIGHEST degrees, at which its buildings' picture fills
// the view's height as well as its width, so the picture is its buildings, not a strip of
// them between the paving and the sky (a block seen from 12 degrees filled a quarter of
// it); if none does, from DISTRICT_HIGHEST (a front view, not a plan), every building
// whole. A facade, or a view that gives its elevation, is framed whole too.
const DISTRICT_LOWEST = 10, DISTRICT_HIGHEST = 30;
function districtRise(points, centre, district, rise) {
  if (!district || !Number.isFinite(around) || Number.isFinite(up)) return or(up, rise);
  for (let degrees = DISTRICT_LOWEST; degrees < DISTRICT_HIGHEST; degrees++) {
    if (fitBox(points, centre, direction(around, degrees)).filled) return degrees;
  }
  return DISTRICT_HIGHEST;
}
function frame(model) {  // seen from 35 degrees round; a facade from 8.5 up, a district from 30
  resize();
  const {box, size, centre, radius, district, rise, points} = bounds(model);
  let target, distance;
  const inDistrict = street && district ? fitDistrictStreet(model, box) : null;
  if (inDistrict) {
    target = inDistrict.aim; distance = inDistrict.distance;
    camera.position.copy(inDistrict.position);
  } else if (street) {
    const fit = fitStreet(box, centre, or(around, SEEN_FROM));
    target = fit.aim; distance = fit.distance;
    camera.position.copy(fit.position);
  } else {
    const elevation = districtRise(points, centre, district, rise);
    const seen = direction(or(around, SEEN_FROM), elevation);
    // from above, the sky over the district's horizon at the picture's top
    const fit = fitBox(points, centre, seen,
                       district && elevation > camera.fov / 2 ? SKY_BAND : 0);
    target = fit.aim;
    if (Number.isFinite(atX)) target.x = box.min.x + atX * size.x;
    if (Number.isFinite(atY)) target.y = box.min.y + atY * size.y;
    if (Number.isFinite(atZ)) target.z = box.min.z + atZ * size.z;
    distance = fit.distance / or(zoom, 1);
    camera.position.copy(target).addScaledVector(seen, distance);
  }
  camera.near = distance / 1000; camera.far = distance * 20 + 8 * radius;
  controls.maxDistance = distance * 10;
  camera.updateProjectionMatrix();
  controls.target.copy(target); controls.update();
  moved = false;
  redraw();
}
function show(id, keep = false) {  // keep: the camera where the user turned it, if they did
  const mine = ++asked;
  status.textContent = 'loading the model';
  let bytes;
  try { bytes = bytesOf(id); } catch (error) {
    status.textContent = 'cannot show the model: ' + error; return;
  }
  new GLTFLoader().parse(bytes.buffer, '', gltf => {
    if (mine !== asked) { dispose(gltf.scene); return; }
    if (shown) { scene.remove(shown); dispose(shown); }
    shown = gltf.scene;
    castsShadows(shown);
    scene.add(shown);
    landCover = landCoverOf(id);  // drawn by light() (groundRegions)
    light(shown);
    if (!(keep && moved)) frame(shown);
    status.textContent = 'drag to orbit, scroll to zoom';
    document.title = document.title.replace('loading: ', '');
  }, error => {
    if (mine === asked) status.textContent = 'cannot show the model: ' + error;
  });
}
resize();
window.facadeShow = show;  // for a page's own scripts (facade watch swaps the model)
"""
VIEWER += GROUND  # the ground under a district (facadecli.viewer.ground)
VIEWER += COVER + COVER_DRAWN  # the land cover on it (facadecli.viewer.landcover)

STYLE = (
    "body{margin:0;font-family:sans-serif;display:flex;height:100vh;background:#f4f4f4}"
    "#model{flex:3;min-width:0}#side{flex:2;overflow:auto;padding:12px;background:#fff}"
    "#side svg,#side img{width:100%;height:auto}"
    ".bare #side,.bare #list{display:none}"
)


def document_parts(title: str, style: str, body: Iterable[str], script: str) -> Iterator[str]:
    """A whole page, piece by piece: the viewer's imports in the head, ``body``, then the
    viewer's script followed by ``script`` (the page's own code, which calls ``show``)."""
    yield (
        '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>loading: {escape(title)}</title><style>{STYLE}{style}</style>"
        f"<!-- three.js {THREE_VERSION}, MIT licence, (c) 2010-2024 three.js authors -->"
        f'<script type="importmap">{import_map()}</script></head><body>'
    )
    yield from body
    yield f'<script type="module">{VIEWER}{script}</script></body></html>\n'


def glb_element(element_id: str, glb: bytes) -> str:
    """A model in the page: the element ``show(element_id)`` reads."""
    return (
        f'<script id="{escape(element_id)}" type="application/octet-stream">'
        f"{base64.b64encode(glb).decode()}</script>"
    )


def page(name: str, glb: bytes, svg: str) -> str:
    """The HTML page of one layout: its glb and its SVG elevation, inlined."""
    elevation = svg.split("?>", 1)[-1]  # inline SVG: no XML declaration
    body = (
        f'<div id="model"></div><div id="side"><h3>{escape(name)}</h3>'
        f'<p id="status">drag to orbit, scroll to zoom</p>{elevation}</div>'
        + glb_element("glb", glb)
    )
    return "".join(document_parts(name, "", [body], "show('glb');\n"))
