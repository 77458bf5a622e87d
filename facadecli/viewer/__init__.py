"""A self-contained HTML page of a layout: the model with orbit controls beside the front
elevation, readable in any browser with no network (three.js r160, MIT licence, is
bundled here from npm and inlined into every page; see LICENSE-three.txt)."""

from __future__ import annotations

import base64
import json
from importlib import resources
from xml.sax.saxutils import escape

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


SCRIPT = """
import * as THREE from 'three';
import {GLTFLoader} from 'three/addons/loaders/GLTFLoader.js';
import {OrbitControls} from 'three/addons/controls/OrbitControls.js';
const view = document.getElementById('model');
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
window.addEventListener('resize', resize);
const text = atob(document.getElementById('glb').textContent);
const bytes = Uint8Array.from(text, c => c.charCodeAt(0));
new GLTFLoader().parse(bytes.buffer, '', gltf => {
  scene.add(gltf.scene);
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length();
  const angle = 35 * Math.PI / 180;
  camera.position.set(centre.x + Math.sin(angle) * size * 1.3, centre.y + size * 0.2,
                      centre.z + Math.cos(angle) * size * 1.3);
  controls.target.copy(centre); controls.update();
  resize();
  renderer.setAnimationLoop(() => { controls.update(); renderer.render(scene, camera); });
  document.title = document.title.replace('loading: ', '');
}, error => { document.getElementById('status').textContent = 'cannot show the model: ' + error; });
"""

STYLE = (
    "body{margin:0;font-family:sans-serif;display:flex;height:100vh;background:#f4f4f4}"
    "#model{flex:3;min-width:0}#side{flex:2;overflow:auto;padding:12px;background:#fff}"
    "#side svg{width:100%;height:auto}"
)


def page(name: str, glb: bytes, svg: str) -> str:
    """The HTML page of one layout: its glb and its SVG elevation, inlined."""
    imports = json.dumps({"imports": {spec: _module(file) for spec, file in MODULES.items()}})
    elevation = svg.split("?>", 1)[-1]  # inline SVG: no XML declaration
    return (
        '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>loading: {escape(name)}</title><style>{STYLE}</style>"
        f"<!-- three.js {THREE_VERSION}, MIT licence, (c) 2010-2023 three.js authors -->"
        f'<script type="importmap">{imports}</script></head><body>'
        f'<div id="model"></div><div id="side"><h3>{escape(name)}</h3>'
        f'<p id="status">drag to orbit, scroll to zoom</p>{elevation}</div>'
        '<script id="glb" type="application/octet-stream">'
        f"{base64.b64encode(glb).decode()}</script>"
        f'<script type="module">{SCRIPT}</script></body></html>\n'
    )
