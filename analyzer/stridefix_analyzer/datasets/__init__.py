"""Importers of public data sets behind one protocol (:mod:`.protocol`), and their registry.

Every module of this package that defines ``DATASET`` (an instance of
:class:`~.protocol.Dataset`) is a data set: :func:`get` and :func:`names` find it without a list to
edit, so ``stridefix import``, ``stridefix-lab realbench --format`` and crowd's walks pick a new set up
from its module alone. :func:`register` adds one from elsewhere (a plug-in, a test).
"""

from __future__ import annotations

import importlib
import pkgutil

from stridefix_analyzer.datasets.protocol import Dataset, UnknownDatasetError

_registry: dict[str, Dataset] = {}
_scanned: list[bool] = []


def _scan() -> None:
    """Import this package's modules once and register each ``DATASET``."""
    if _scanned:
        return
    _scanned.append(True)
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}")
        dataset = getattr(module, "DATASET", None)
        if isinstance(dataset, Dataset):
            _registry.setdefault(dataset.name, dataset)


def register(dataset: Dataset, *, replace: bool = False) -> Dataset:
    """Add ``dataset`` under its name; returns it. Raises ValueError when the name is taken
    (unless ``replace``)."""
    _scan()
    if dataset.name in _registry and not replace and _registry[dataset.name] is not dataset:
        raise ValueError(f"a data set named {dataset.name!r} is already registered")
    _registry[dataset.name] = dataset
    return dataset


def unregister(name: str) -> None:
    """Remove the data set ``name`` (no error when there is none)."""
    _registry.pop(name, None)


def names() -> tuple[str, ...]:
    """Every data set's name, in listing order."""
    _scan()
    return tuple(sorted(_registry, key=lambda n: (_registry[n].list_order, n)))


def get(name: str) -> Dataset:
    """The data set ``name``. Raises :class:`~.protocol.UnknownDatasetError`."""
    _scan()
    try:
        return _registry[name]
    except KeyError:
        raise UnknownDatasetError(f"unknown format {name!r}; known: {', '.join(names())}") from None
