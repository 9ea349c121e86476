"""``anthroarm cache``: the disk cache of generated code (parser; the run: :mod:`.cache_run`)."""

from __future__ import annotations

from .common import add_json


def add_parser(sub):
    p = sub.add_parser(
        "cache",
        help="show or empty the cache of generated code",
        description="The disk cache of generated Lagrange code and compiled C kernels "
        "($ANTHROARM_CACHE, else $XDG_CACHE_HOME/anthroarm, else the user cache folder).",
        epilog="examples: anthroarm cache info --json; anthroarm cache clear",
    )
    p.add_argument(
        "action",
        choices=["info", "clear"],
        help="info: folder, entries, size and whether it is used; clear: delete the cache's "
        "own files (refused, exit status 2, if the folder is a link, another user's, or "
        "writable by group or others)",
    )
    add_json(p, "print as JSON")
    p.set_defaults(run="cache_run.run")
