"""Self-contained HTML pages of models: one layout's model with orbit controls beside its
front elevation (``--format html``), or a gallery of every model in a folder
(``facade view``, :mod:`facadecli.viewer.gallery`). Readable in any browser with no
network: three.js r160 (MIT licence) is bundled here from npm and inlined into every page
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

THREE_VERSION = "0.160.0"
# specifier -> bundled file; relative imports between the files are made bare specifiers
MODULES = {
    "three": "three.module.min.js",
    "three/addons/utils/BufferGeometryUtils.js": "BufferGeometryUtils.js",
    "three/addons/loaders/GLTFLoader.js": "GLTFLoader.js",
    "three/addons/controls/OrbitControls.js": "OrbitControls.js",
}
RELATIVE = {"'../utils/BufferGeometryUtils.js'": "'three/addons/utils/BufferGeometryUtils.js'"}


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
const view = document.getElementById('model');
const status = document.getElementById('status');
const renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xdddddd);
scene.add(new THREE.HemisphereLight(0xffffff, 0x666666, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.position.set(5, 10, 8);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 5000);
const controls = new OrbitControls(camera, renderer.domElement);
function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h); camera.aspect = w / h; camera.updateProjectionMatrix();
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
// ?view=ANGLE,ELEVATION,ZOOM,X,Y: seen from ANGLE degrees around and ELEVATION up, ZOOM
// times closer, looking at the point X, Y (0..1 across the model); ?bare: the model alone
const query = new URLSearchParams(location.search);
const [around, up, zoom, atX, atY] = (query.get('view') || '').split(',').map(parseFloat);
const or = (value, fallback) => Number.isFinite(value) ? value : fallback;
if (query.has('bare')) document.body.classList.add('bare');
function frame(model) {  // the model's bounding sphere fills the view, seen from 35 degrees
  resize();
  const box = new THREE.Box3().setFromObject(model);
  const centre = box.isEmpty() ? new THREE.Vector3() : box.getCenter(new THREE.Vector3());
  const size = box.isEmpty() ? 10 : Math.max(box.getSize(new THREE.Vector3()).length(), 0.01);
  if (!box.isEmpty()) {
    centre.x = box.min.x + or(atX, 0.5) * (box.max.x - box.min.x);
    centre.y = box.min.y + or(atY, 0.5) * (box.max.y - box.min.y);
  }
  const vertical = camera.fov * Math.PI / 180;
  const horizontal = 2 * Math.atan(Math.tan(vertical / 2) * camera.aspect);
  const distance = 1.1 * (size / 2) / Math.sin(Math.min(vertical, horizontal) / 2) / or(zoom, 1);
  const angle = or(around, 35) * Math.PI / 180, rise = or(up, 8.5) * Math.PI / 180;
  const direction = new THREE.Vector3(
    Math.sin(angle) * Math.cos(rise), Math.sin(rise), Math.cos(angle) * Math.cos(rise));
  camera.position.copy(centre).addScaledVector(direction, distance);
  camera.near = distance / 1000; camera.far = distance * 20; controls.maxDistance = distance * 10;
  camera.updateProjectionMatrix();
  controls.target.copy(centre); controls.update();
  moved = false;
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
    scene.add(shown);
    if (!(keep && moved)) frame(shown);
    status.textContent = 'drag to orbit, scroll to zoom';
    document.title = document.title.replace('loading: ', '');
  }, error => {
    if (mine === asked) status.textContent = 'cannot show the model: ' + error;
  });
}
resize();
renderer.setAnimationLoop(() => { controls.update(); renderer.render(scene, camera); });
window.facadeShow = show;  // for a page's own scripts (facade watch swaps the model)
"""

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
        f"<!-- three.js {THREE_VERSION}, MIT licence, (c) 2010-2023 three.js authors -->"
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
