"""``anthroarm cache``: the run (the parser: :mod:`.cache`)."""

from __future__ import annotations

import json

from .. import cache


def run(a) -> int:
    if a.action == "clear":
        where = str(cache.configured())  # the folder asked for; clear() refuses an unsafe one
        n = cache.clear()
        print(
            json.dumps({"folder": where, "removed": n})
            if a.json
            else f"removed {n} entries from {where}"
        )
        return 0
    i = cache.info()
    if a.json:
        print(json.dumps(i, indent=1))
    else:
        print(f"folder  {i['folder']}")
        print(f"entries {i['entries']} ({i['bytes'] / 1e6:.2f} MB)")
        for sub, (n, size) in i["by_folder"].items():
            print(f"  {sub:<9} {n:4d} entries {size / 1e6:8.2f} MB")
        print(f"status  {i['status']}")
    return 0
