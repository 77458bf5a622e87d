"""USD of a layout (``--format usd``): a ``.usda`` text stage for Houdini, Omniverse, Blender
and the rest of the USD world, written without USD's own library.

- The default prim is the façade (an Xform, kind ``component``, metres, Y up as the glTF),
  with an Xform per layer, and under it an Xform per part of a shape, placed by its matrix.
- Repeated parts are instanced: each distinct mesh is an Xform holding a Mesh under the
  abstract class ``/<name>/Prototypes`` (points, triangles, face-varying normals, UVs
  where it has them, its extent), and every part that uses it is an instanceable Xform
  referencing it, with its own transform.
- Materials are UsdPreviewSurface shaders under ``/<name>/Materials`` with the glTF's base
  colour, metallic, roughness and opacity; every prototype is bound to its material. A
  library material's inputs read UsdUVTextures of its PNG pictures, written beside the
  stage.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path

import numpy as np
import trimesh

from facadecli.city.folders import id_digest
from facadecli.export.atomic import write_atomic
from facadecli.export.obj import ordered_nodes
from facadecli.export.texture_store import TextureStore
from facadecli.export.textures import SLOTS, TextureFiles, texture_files


def usd_name(text: str) -> str:
    """A name USD accepts for a prim: letters, digits and underscores, not starting with a
    digit."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", text) or "_"
    return name if not name[0].isdigit() else "_" + name


def _floats(values: np.ndarray) -> str:
    return ", ".join(f"{float(v):.9g}" for v in values)


def _tuples(rows: np.ndarray) -> str:
    return "[" + ", ".join(f"({_floats(row)})" for row in rows) + "]"


def _material(
    name: str, material: object, root: str, pictures: dict[str, str] | None = None
) -> list[str]:
    """A UsdPreviewSurface; with ``pictures`` (slot -> file beside the stage, for a
    drawn material), its inputs read from UsdUVTextures over the mesh's ``st``."""
    colour = getattr(material, "baseColorFactor", None)
    rgba = (
        np.array(colour, dtype=float) / (255.0 if np.max(colour) > 1.0 else 1.0)
        if colour is not None
        else np.array([0.75, 0.75, 0.75, 1.0])
    )
    metallic = getattr(material, "metallicFactor", None) or 0.0
    roughness = getattr(material, "roughnessFactor", None)
    roughness = 1.0 if roughness is None else roughness
    path = f"{root}/Materials/{name}"
    reads = f"{path}/base_colour.outputs:rgb"
    glow = getattr(material, "emissiveFactor", None)  # a lit room: its base colour, dimmed
    if pictures:
        inputs = [
            f"                color3f inputs:diffuseColor.connect = <{reads}>",
            f"                normal3f inputs:normal.connect = <{path}/normal.outputs:rgb>",
            f"                float inputs:metallic.connect = <{path}/orm.outputs:b>",
            f"                float inputs:roughness.connect = <{path}/orm.outputs:g>",
            f"                float inputs:occlusion.connect = <{path}/orm.outputs:r>",
        ]
        if glow is not None:
            emission = f"{path}/emission.outputs:rgb"
            inputs.append(f"                color3f inputs:emissiveColor.connect = <{emission}>")
            pictures = {**pictures, "emission": pictures["base_colour"]}
    else:
        inputs = [
            f"                color3f inputs:diffuseColor = ({_floats(rgba[:3])})",
            f"                float inputs:metallic = {metallic:.6g}",
            f"                float inputs:roughness = {roughness:.6g}",
        ]
        if glow is not None:
            inputs.append(
                f"                color3f inputs:emissiveColor = ({_floats(np.asarray(glow))})"
            )
    lines = [
        f'        def Material "{name}"',
        "        {",
        f"            token outputs:surface.connect = <{path}/Surface.outputs:surface>",
        '            def Shader "Surface"',
        "            {",
        '                uniform token info:id = "UsdPreviewSurface"',
        *inputs,
        f"                float inputs:opacity = {rgba[3]:.6g}",
        "                token outputs:surface",
        "            }",
    ]
    if pictures:
        lines += _texture_network(path, pictures, glow)
    return [*lines, "        }"]


def _texture_network(
    path: str, pictures: dict[str, str], glow: Sequence[float] | None = None
) -> list[str]:
    """The ``st`` reader and a UsdUVTexture per picture (normals from 0..1 to -1..1, raw:
    only the base colour is sRGB; ``emission``, the base colour scaled by ``glow``)."""
    lines = [
        '            def Shader "st"',
        "            {",
        '                uniform token info:id = "UsdPrimvarReader_float2"',
        '                string inputs:varname = "st"',
        "                float2 outputs:result",
        "            }",
    ]
    for slot, file in pictures.items():
        space = "sRGB" if slot in ("base_colour", "emission") else "raw"
        lines += [
            f'            def Shader "{slot}"',
            "            {",
            '                uniform token info:id = "UsdUVTexture"',
            f"                asset inputs:file = @{_asset(file)}@",
            f"                float2 inputs:st.connect = <{path}/st.outputs:result>",
            f'                token inputs:sourceColorSpace = "{space}"',
            '                token inputs:wrapS = "repeat"',
            '                token inputs:wrapT = "repeat"',
        ]
        if slot == "normal":
            lines += [
                "                float4 inputs:scale = (2, 2, 2, 1)",
                "                float4 inputs:bias = (-1, -1, -1, 0)",
            ]
        if slot == "emission" and glow is not None:
            lines.append(f"                float4 inputs:scale = ({_floats(np.asarray(glow))}, 1)")
        lines += [
            "                float3 outputs:rgb",
            "                float outputs:r",
            "                float outputs:g",
            "                float outputs:b",
            "            }",
        ]
    return lines


def _asset(file: str) -> str:
    """A picture's asset path, relative to the stage: ``./name.png`` beside it, or the
    relative path of a run's shared picture (``../../textures/<digest>.png``)."""
    return file if file.startswith("../") else f"./{file}"


def _mesh(name: str, mesh: trimesh.Trimesh, material: str, root: str) -> list[str]:
    faces = mesh.faces
    normals = np.repeat(mesh.face_normals, 3, axis=0)
    indices = ", ".join(str(int(i)) for i in faces.ravel())
    lines = [
        f'        def Xform "{name}"',
        "        {",
        '            def Mesh "mesh" (',
        '                prepend apiSchemas = ["MaterialBindingAPI"]',
        "            )",
        "            {",
        f"                float3[] extent = {_tuples(mesh.bounds)}",
        f"                int[] faceVertexCounts = [{', '.join(['3'] * len(faces))}]",
        f"                int[] faceVertexIndices = [{indices}]",
        f"                point3f[] points = {_tuples(mesh.vertices)}",
        f"                normal3f[] normals = {_tuples(normals)} (",
        '                    interpolation = "faceVarying"',
        "                )",
    ]
    uv = getattr(mesh.visual, "uv", None)
    if uv is not None and len(uv) == len(mesh.vertices):
        lines += [
            f"                texCoord2f[] primvars:st = {_tuples(uv)} (",
            '                    interpolation = "vertex"',
            "                )",
        ]
    lines += [
        f"                rel material:binding = <{root}/Materials/{material}>",
        '                uniform token subdivisionScheme = "none"',
        "            }",
        "        }",
    ]
    return lines


def usda_text(scene: trimesh.Scene, name: str, pictures: TextureFiles | None = None) -> str:
    """The scene as a USD stage (see the module); ``pictures`` names the files of the drawn
    materials' textures, by the materials' own names."""
    root = f"/{usd_name(name)}"
    prototypes: dict[str, str] = {}  # geometry key -> prototype prim name
    materials: dict[str, object] = {}
    meshes: list[str] = []
    for key in sorted(scene.geometry):
        mesh = scene.geometry[key]
        material = getattr(mesh.visual, "material", None)
        material_name = usd_name(getattr(material, "name", None) or "default")
        materials.setdefault(material_name, material)
        prototypes[key] = usd_name(f"m_{key}")
        meshes += _mesh(prototypes[key], mesh, material_name, root)
    layers: dict[str, list[str]] = {}
    for node in ordered_nodes(scene):
        matrix, key = scene.graph[node]
        layer = usd_name(node.split("/", 1)[0])
        rows = np.asarray(matrix, dtype=float).T  # USD: row vectors, translation last
        transform = ", ".join(f"({_floats(row)})" for row in rows)
        layers.setdefault(layer, []).extend(
            [
                f'        def Xform "{usd_name(node)}" (',
                "            instanceable = true",
                f"            prepend references = <{root}/Prototypes/{prototypes[key]}>",
                "        )",
                "        {",
                f"            matrix4d xformOp:transform = ({transform})",
                '            uniform token[] xformOpOrder = ["xformOp:transform"]',
                "        }",
            ]
        )
    out = [*_head(name, "component"), '    def Scope "Materials"', "    {"]
    names = pictures.names if pictures else {}
    for material_name, material in materials.items():
        own = getattr(material, "name", None) or "default"
        files = {slot: names[(own, slot)] for slot in SLOTS if (own, slot) in names}
        out += _material(material_name, material, root, files)
    out += ["    }", '    class Scope "Prototypes"', "    {", *meshes, "    }"]
    for layer, prims in layers.items():
        out += [f'    def Xform "{layer}"', "    {", *prims, "    }"]
    out.append("}")
    return "\n".join(out) + "\n"


def _head(name: str, kind: str) -> list[str]:
    """A stage's metadata (metres, Y up) and the opening of its default prim."""
    return [
        "#usda 1.0",
        "(",
        f'    defaultPrim = "{usd_name(name)}"',
        "    metersPerUnit = 1",
        '    upAxis = "Y"',
        ")",
        "",
        f'def Xform "{usd_name(name)}" (',
        f'    kind = "{kind}"',
        ")",
        "{",
    ]


def write_usd(scene: trimesh.Scene, path: Path) -> list[Path]:
    """The stage, and beside it the PNG pictures of its drawn materials."""
    pictures = texture_files(_materials(scene), path.stem)
    written = []
    for file, data in pictures.files.items():
        write_atomic(path.parent / file, data)
        written.append(path.parent / file)
    write_atomic(path, usda_text(scene, path.stem, pictures))
    return [path, *written]


def stored_usda_text(scene: trimesh.Scene, path: Path, store: TextureStore) -> str:
    """The stage to be written at ``path``, its pictures in a run's ``store`` (each
    written once for the run, texture_store.py) instead of beside it."""
    pictures = texture_files(_materials(scene), path.stem)
    names = {key: store.uri(pictures.files[file], path) for key, file in pictures.names.items()}
    return usda_text(scene, path.stem, TextureFiles(names, {}))


def _materials(scene: trimesh.Scene) -> list[tuple[str, object]]:
    """The scene's materials by name, in the order of its meshes' names."""
    found: dict[str, object] = {}
    for key in sorted(scene.geometry):
        material = getattr(scene.geometry[key].visual, "material", None)
        found.setdefault(getattr(material, "name", None) or "default", material)
    return list(found.items())


def city_usda(name: str, buildings: Iterable[Path], folder: Path) -> str:
    """A city's stage: an Xform per building with its stage as a payload (loaded when a
    tool asks for it, so a city of thousands opens at once), in the city's frame."""
    return "".join(city_usda_lines(name, buildings, folder))


def city_usda_lines(name: str, buildings: Iterable[Path], folder: Path) -> Iterator[str]:
    """:func:`city_usda` a line at a time (each with its newline), the buildings taken as
    they come: a city of any size is written without its text held, nor its prims'
    names (:func:`building_prim`: unique by construction)."""
    for line in _head(name, "assembly"):
        yield line + "\n"
    for glb in buildings:
        stage = glb.with_suffix(".usda").relative_to(folder).as_posix()
        prim = building_prim(glb.stem)
        yield f'    def Xform "{prim}" (\n        prepend payload = @./{stage}@\n'
        yield "    )\n    {\n    }\n"
    yield "}\n"


HASHED = re.compile(r".+_[0-9a-f]{16}")  # a prim name ending as a hashed file name's does


def building_prim(stem: str) -> str:
    """A building's prim name in a city's stage, from its file name (``stem``, a
    :func:`facadecli.city.folders.safe_name`, each a different one in a run).

    - A hashed name (``<readable>~<16 hex digits of the id's SHA-256>``) gives
      :func:`usd_name` of it: the readable part, ``_`` and the hash.
    - A plain name (the id itself: lower-case letters, digits and ``._-``) gives itself
      (``_`` in front of a leading digit), unless it holds ``.`` or ``-`` (both read
      ``_``) or reads like a hashed one: then it takes ``_`` and the hash too.

    So two different names never give one prim: those without a hash are the plain names
    of ``[a-z0-9_]`` as they are (a leading ``_`` marks a digit: none starts with ``_``),
    and they never end as HASHED; those with one differ in it, unless two ids' hashes
    share 64 bits (the chance that a file name of :func:`.safe_name` relies on too). No
    list of the names given is needed to keep them apart."""
    name = usd_name(stem)
    if "~" not in stem and ("." in stem or "-" in stem or HASHED.fullmatch(name)):
        name += "_" + id_digest(stem)[:16]
    return name
