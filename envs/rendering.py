"""The lifecycle of an offscreen renderer owned by a world.

A MuJoCo renderer holds a GL context: it is made on the first ``render()``,
freed by ``close()``, and never pickled (a copied or spawned world makes its
own when it first renders).
"""

from __future__ import annotations

from typing import Any


class OwnsRenderer:
    """Mixin for a class keeping its renderer (anything with ``close()``) in ``_renderer``."""

    _renderer: Any = None

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state
