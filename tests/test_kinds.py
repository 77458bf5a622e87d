"""What ``facade view`` inlines is what its name says: glTF binary, SVG without a DTD, PNG
(:mod:`facadecli.viewer.kinds`), checked on small hand-made files."""

from __future__ import annotations

import json
import struct

import pytest

from facadecli.viewer.kinds import glb_problem, kind_problem, png_problem, svg_problem

SVG = '<svg xmlns="http://www.w3.org/2000/svg" width="1" height="1"><rect/></svg>'


def _glb(
    document: object, version: int = 2, extra: bytes = b"", length: int | None = None
) -> bytes:
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + extra
    total = 12 + len(chunks) if length is None else length
    return b"glTF" + struct.pack("<II", version, total) + chunks


GOOD = {"asset": {"version": "2.0"}}


def test_a_glb_is_glTF_2_with_a_json_chunk() -> None:
    assert glb_problem(_glb(GOOD)) is None
    binary = struct.pack("<II", 4, 0x004E4942) + b"\0\0\0\0"
    assert glb_problem(_glb(GOOD, extra=binary)) is None
    assert "version 1" in str(glb_problem(_glb(GOOD, version=1)))
    assert "header says" in str(glb_problem(_glb(GOOD, length=10_000)))
    assert "does not start" in str(glb_problem(b"root:x:0:0:root:/root:/bin/bash\n"))
    assert "past the end" in str(glb_problem(_glb(GOOD, extra=struct.pack("<II", 99, 1))))
    assert "cut short" in str(glb_problem(_glb(GOOD, extra=b"\0\0\0\0")))
    assert "not JSON" in str(glb_problem(_glb(GOOD).replace(b"}}", b"]]")))
    assert "asset.version" in str(glb_problem(_glb({"asset": {"version": "1.0"}})))
    assert "asset.version" in str(glb_problem(_glb([1, 2])))
    first_binary = b"glTF" + struct.pack("<IIII", 2, 24, 4, 0x004E4942) + b"abcd"
    assert "first chunk is not JSON" in str(glb_problem(first_binary))


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ("root:x:0:0:root", "not XML"),
        ('<html xmlns="http://www.w3.org/1999/xhtml"/>', "root element"),
        ("<svg/>", "root element"),  # no SVG namespace: no browser draws it as an image
        (
            '<!DOCTYPE svg [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
            '<svg xmlns="http://www.w3.org/2000/svg">&x;</svg>',
            "DTD",
        ),
        (
            '<!DOCTYPE s [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;">]>'
            '<svg xmlns="http://www.w3.org/2000/svg">&b;</svg>',
            "DTD",
        ),
        ('<!DOCTYPE svg SYSTEM "http://example.org/x.dtd"><svg/>', "DTD"),
        ('<svg xmlns="http://www.w3.org/2000/svg">&x;</svg>', "not XML"),
    ],
)
def test_an_svg_is_xml_with_an_svg_root_and_no_dtd(text: str, why: str) -> None:
    assert svg_problem(SVG.encode()) is None
    assert why in str(svg_problem(text.encode()))


def test_a_png_starts_with_its_signature_and_other_names_are_refused() -> None:
    assert png_problem(b"\x89PNG\r\n\x1a\n" + b"\0" * 20) is None
    assert "signature" in str(png_problem(b"GIF89a"))
    assert kind_problem(".SVG", SVG.encode()) is None
    assert kind_problem(".txt", b"hello") is not None
