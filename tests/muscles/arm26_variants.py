"""arm26 (shipped) edited for the muscle tests: written to a file beside the test's ``tmp_path``,
its ellipsoids made inactive or made spheres, its TRI cylinder made one-sided."""

from __future__ import annotations

import re

import anthroarm as aa


def variant(tmp_path, name, *edits):
    """arm26's text through ``edits`` (each text -> text), written to ``tmp_path/name.osim``."""
    text = aa.osim.path("arm26").read_text()
    for edit in edits:
        text = edit(text)
    p = tmp_path / f"{name}.osim"
    p.write_text(text)
    return p


def no_ellipsoids(text):
    """Both WrapEllipsoids inactive."""
    out = re.sub(r"(<WrapEllipsoid name=\"\w+\">\s*<!--[^>]*-->\s*<active>)true", r"\1false", text)
    assert out.count("<active>false</active>") == 2
    return out


def spheres(text):
    """Both WrapEllipsoids made WrapSpheres of radius 2 cm."""
    text = text.replace("<WrapEllipsoid", "<WrapSphere").replace(
        "</WrapEllipsoid>", "</WrapSphere>"
    )
    return re.sub(r"<dimensions>[^<]*</dimensions>", "<radius>0.02</radius>", text)


def tri_quadrant(quadrant):
    """An edit setting the TRI cylinder's quadrant (``all`` in the file) to ``quadrant``."""

    def edit(text):
        pattern = r'(<WrapCylinder name="TRI">.*?<quadrant>)all(</quadrant>)'
        out = re.sub(pattern, rf"\g<1>{quadrant}\2", text, flags=re.S)
        assert out != text
        return out

    return edit
