"""Resource limits: what facadecli accepts, in one place (the README's table lists them).

Each limit keeps one bad input from taking the machine down (memory, time) and is enforced
where the input is read, with a message that names the limit.
"""

from __future__ import annotations

CANVAS_MAX = 1000.0  # metres: the longest side of a façade canvas
LENGTH_MAX = 1000.0  # metres: any other length of a spec (sizes, depths, offsets, ...), +/-
COUNT_MAX = 10_000  # a counter's bounds, a fixed count in a pattern
SPEC_BYTES_MAX = 512 * 1024  # bytes of one spec file (or a city manifest)
SPEC_VALUES_MAX = 100_000  # values a spec's YAML may expand to (aliases count each time)
SPEC_DEPTH_MAX = 64  # nesting of a spec's YAML
MESH_BYTES_MAX = 32_000_000  # bytes of one mesh file named by a spec
MESH_FACES_MAX = 200_000  # triangles of one mesh file (each instance in its scene counted)
GLTF_NODES_MAX = 2048  # nodes of one glTF mesh file
GLTF_DEPTH_MAX = 32  # levels of a glTF mesh file's node hierarchy
SCENE_FACES_MAX = 5_000_000  # triangles of one façade's model (every shape, every cell)
TEXTURE_PIXELS_MAX = 4096 * 4096  # pixels of one texture image
TEXTURE_SIDE_MAX = 8192  # pixels of a texture's longer side
GEOJSON_BYTES_MAX = 500_000_000  # bytes of a city's footprints file (counted as it is read)
FOOTPRINT_VERTICES_MAX = 1000  # vertices of one footprint: more are simplified
FOOTPRINT_REACH_MAX = 100_000.0  # metres from the (low) median of the others: a wrong value
PROJECTED_MAX = 1e8  # a projected coordinate (in its CRS's unit)
BUILDING_HEIGHT_MAX = 1000.0  # metres: a taller height tag is ignored, with a warning
BUILDING_LEVELS_MAX = 300  # more levels in a tag are ignored, with a warning
OSM_XML_BYTES_MAX = 500_000_000  # bytes of an OSM XML extract, inflated when compressed
OSM_INFLATION_MAX = 100  # bytes a byte of a compressed extract may inflate to (gz, bz2, pbf)
OSM_INFLATION_FREE = 16 * 1024 * 1024  # inflated bytes allowed whatever the ratio
OSM_TEXT_CHARS_MAX = 255  # characters of an OSM tag key or value, role or user (OSM's own)
OSM_ID_MAX = 2**62 - 1  # an OSM id or reference, either sign (libosmium's area ids double it)
GPKG_ROWS_MAX = 1_000_000  # rows read from a GeoPackage's feature table
GPKG_STEPS_PER_BYTE = 100  # SQLite steps reading the feature table, a byte of the file
GPKG_STEPS_FREE = 50_000_000  # SQLite steps allowed whatever the file's size
GPKG_BYTES_FREE = 16 * 1024 * 1024  # bytes of values read from a feature table past the file's
LAYOUT_BYTES_MAX = 32_000_000  # bytes of one layout file read by ``facade grammar``
LAYOUT_RECTS_MAX = 20_000  # rectangles of one layout
LAYOUT_EXTENT_MAX = 1e6  # a layout's size and any coordinate, in the file's own units
LAYOUT_CELLS_MAX = 1_000_000  # cells of a snapped tiling (1000 x 1000)
GRAMMAR_WORK_MAX = 30_000_000  # work units of one grammar search (a cell read into a content: 1)
GRAMMAR_DEPTH_MAX = 400  # rules nested in a grammar (each derived, written, varied in turn)
LABEL_CHARS_MAX = 100  # characters of a label
HINT_NAME_CHARS_MAX = 200  # characters of an unknown name that gets a "did you mean" hint
GALLERY_BYTES_MAX = 256 * 1024 * 1024  # bytes of the models a ``facade view`` page inlines
WATCH_CONNECTIONS_MAX = 32  # connections ``facade watch`` serves at once (more: closed)
WATCH_STREAMS_MAX = 8  # of those, open event streams (pages following the spec; more: 503)
WATCH_IDLE_SECONDS = 10.0  # a connection that sends or takes nothing this long is closed
WATCH_REQUEST_SECONDS = 10.0  # a request's line and headers arrive within this, in all

#: bytes of a city's single merged glb (a glb's lengths are 32-bit); beyond, tiles only
MERGED_GLB_MAX = 2**31
#: buildings of a city's single merged glb: a bigger city is more than a viewer loads at
#: once, so it gets tiles only (``tiles/``, and ``--3dtiles``, which a viewer streams)
MERGED_BUILDINGS_MAX = 10_000
