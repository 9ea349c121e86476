"""The channel of a :class:`~anthroarm.viewer.Viewer`: every command updates the in-memory
scene (:class:`~anthroarm.viewer._store.SceneStore`, so the HTML export never needs a server)
and, when the viewer is live, goes to its server process
(:class:`~anthroarm.viewer.server.ServerProcess`, 127.0.0.1 only) as one message.

:class:`LiveMixin` is one part of :class:`~anthroarm.viewer.Viewer`.
"""

from __future__ import annotations

import webbrowser


class LiveMixin:
    """The in-memory scene and the live server: sending, the URL, the browser tab, closing (a
    part of :class:`~anthroarm.viewer.Viewer`)."""

    def _send(self, cmds: list[dict]) -> None:
        if not cmds:
            return
        for c in cmds:
            self.store.apply(c)
        if self.server is not None:
            self.server.send_many(cmds)

    @property
    def url(self) -> str | None:
        """Browser URL of the live server (None when not live)."""
        return self.server.web_url if self.server is not None else None

    def open(self):
        """Open the live scene in the default web browser."""
        if self.server is None:
            raise RuntimeError(
                "this viewer is not live; create it with live=True, or use export_html()"
            )
        webbrowser.open(self.url, new=2)
        return self

    def wait(self, n: int = 1, timeout: float = 30.0) -> None:
        """Block until ``n`` browser tabs are connected to the live server; ViewerError after
        ``timeout`` seconds.  ``n`` in 1..1024 and a finite ``timeout`` in (0, 3600] s
        (:class:`~anthroarm.errors.ParameterError`, a TypeError/ValueError, otherwise)."""
        if self.server is None:
            raise RuntimeError("this viewer is not live")
        self.server.wait(n, timeout)

    def close(self) -> None:
        """Stop the server (if live).  The in-memory scene stays usable for export."""
        if self.server is not None:
            self.server.close()
            self.server = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
