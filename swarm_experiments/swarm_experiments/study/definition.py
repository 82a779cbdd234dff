"""Study definitions and the registry the command line finds them in.

A study is declared once, by the package that owns the algorithm, as a :class:`Study`:

* ``axes``: the parameters that vary, each with its values; the study's configurations are
  their Cartesian product (``{'robots': (2, 4), 'variant': ('gas', 'sound')}`` gives four);
* ``params``: the fixed parameters every run gets (nested mappings allowed), overridable
  from the command line with ``--set``;
* ``runs``: seeds per configuration (``first_seed``, ``first_seed + 1``, ...). The same seed
  in two configurations is the same scenario (site, placement), so results pair by seed;
* ``run``: a module-level callable ``run(spec: RunSpec) -> Mapping`` returning the row's
  metrics (scalars) and time series (1-D sequences); it must be deterministic from the spec;
* ``smoke``: a small variant of the study for ``--smoke`` (fewer axes values, seeds, steps);
* ``report``: an optional hook ``report(page: ReportPage) -> None`` adding the study's own
  tables, plots and paper reference numbers to the generic report.

Packages make their studies known through the ``swarm_experiments.studies`` entry point
group: each entry point loads a callable returning an iterable of :class:`Study`. A module of
one's own can be added on the command line with ``--studies module:function``.
"""

from __future__ import annotations

import importlib
import re
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from typing import TYPE_CHECKING, Any

from .errors import StudyDefinitionError, UsageError

if TYPE_CHECKING:
    from .report import ReportPage
    from .spec import RunSpec

__all__ = ['ENTRY_POINT_GROUP', 'Smoke', 'Study', 'StudyRegistry', 'load_registry']

#: Entry point group through which packages register their studies.
ENTRY_POINT_GROUP = 'swarm_experiments.studies'

_NAME = re.compile(r'^[A-Za-z0-9][A-Za-z0-9_.-]*$')
_SEED_LABELS = ('seed', 'site')


@dataclass(frozen=True)
class Smoke:
    """What ``--smoke`` changes: axes restricted to some values, fewer seeds, parameters."""

    runs: int = 1
    axes: Mapping[str, Sequence[Any]] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Study:
    """A named set of runs: parameter axes x seeds, and the function that runs one."""

    name: str
    run: Callable[[RunSpec], Mapping[str, Any]]
    axes: Mapping[str, Sequence[Any]] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)
    runs: int = 10
    first_seed: int = 0
    seed_label: str = 'seed'
    description: str = ''
    smoke: Smoke = field(default_factory=Smoke)
    report: Callable[[ReportPage], None] | None = None

    def __post_init__(self) -> None:
        if not _NAME.match(self.name):
            raise StudyDefinitionError(
                f'study name {self.name!r}: use letters, digits, "_", "-" and "."'
            )
        if not callable(self.run):
            raise StudyDefinitionError(f'study {self.name}: run is not callable')
        if self.runs < 1:
            raise StudyDefinitionError(f'study {self.name}: runs must be >= 1, not {self.runs}')
        if self.seed_label not in _SEED_LABELS:
            raise StudyDefinitionError(
                f'study {self.name}: seed_label must be one of {_SEED_LABELS}'
            )
        for axis, values in self.axes.items():
            if isinstance(values, str) or not isinstance(values, Sequence) or not values:
                raise StudyDefinitionError(
                    f'study {self.name}: axis {axis!r} needs a non-empty sequence of values'
                )
            if axis in self.params:
                raise StudyDefinitionError(
                    f'study {self.name}: {axis!r} is both an axis and a fixed parameter'
                )
        for axis in self.smoke.axes:
            if axis not in self.axes:
                raise StudyDefinitionError(f'study {self.name}: smoke names unknown axis {axis!r}')


class StudyRegistry:
    """Studies by name; the command line and the report writer look them up here."""

    def __init__(self, studies: Iterable[Study] = ()) -> None:
        self._studies: dict[str, Study] = {}
        for study in studies:
            self.add(study)

    def add(self, study: Study) -> Study:
        """Register ``study``; a second study of the same name is an error."""
        if not isinstance(study, Study):
            raise StudyDefinitionError(f'not a Study: {study!r}')
        if study.name in self._studies:
            raise StudyDefinitionError(f'two studies are named {study.name!r}')
        self._studies[study.name] = study
        return study

    def extend(self, studies: Iterable[Study] | Study) -> None:
        if isinstance(studies, Study):
            studies = [studies]
        for study in studies:
            self.add(study)

    def get(self, name: str) -> Study:
        try:
            return self._studies[name]
        except KeyError:
            known = ', '.join(sorted(self._studies)) or 'none registered'
            raise UsageError(f'no study named {name!r} (known: {known})') from None

    def find(self, name: str) -> Study | None:
        return self._studies.get(name)

    def __iter__(self) -> Iterator[Study]:
        return iter(sorted(self._studies.values(), key=lambda study: study.name))

    def __len__(self) -> int:
        return len(self._studies)

    def __contains__(self, name: object) -> bool:
        return name in self._studies


def _load_reference(reference: str) -> Callable[[], Any]:
    module_name, _, attribute = reference.partition(':')
    if not module_name or not attribute:
        raise UsageError(f'--studies {reference!r}: expected module:function')
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise UsageError(f'--studies {reference!r}: cannot import {module_name} ({exc})') from exc
    try:
        target = getattr(module, attribute)
    except AttributeError:
        raise UsageError(f'--studies {reference!r}: {module_name} has no {attribute}') from None
    return target


def load_registry(extra: Sequence[str] = (), *, use_entry_points: bool = True) -> StudyRegistry:
    """Studies from the installed packages' entry points plus ``module:function`` references.

    Each entry point and each reference is a callable returning a :class:`Study` or an
    iterable of them.
    """
    registry = StudyRegistry()
    providers: list[tuple[str, Callable[[], Any]]] = []
    if use_entry_points:
        for point in entry_points(group=ENTRY_POINT_GROUP):
            providers.append((f'entry point {point.name}', point.load()))
    for reference in extra:
        providers.append((f'--studies {reference}', _load_reference(reference)))
    for origin, provider in providers:
        if not callable(provider):
            raise StudyDefinitionError(f'{origin}: not callable')
        try:
            registry.extend(provider())
        except StudyDefinitionError as exc:
            raise StudyDefinitionError(f'{origin}: {exc}') from exc
    return registry
