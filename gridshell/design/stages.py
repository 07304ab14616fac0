"""Named pipeline stages: a design pipeline as a short list of stage functions.

A :class:`Stage` is one step of a pipeline (read, clean, fit, optimize, trace, post-optimize,
simulate, gate, write) with the names of the values it needs and gives. A pipeline is a tuple
of stages run in order over one ``state`` dict by :func:`run_stages`, which times each stage
(seconds, in ``timings[name]``) and checks that each stage gave what it promised. ``build``,
``sweep`` and the server call, time and cache the same stages by name.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping

Progress = Callable[[str], None] | None


@dataclass(frozen=True)
class Stage:
    """One named step: ``run(state) -> {name: value}`` for every name in ``gives``.

    ``needs`` are the state's keys it reads (checked before it runs), ``gives`` the keys it adds
    or replaces (checked after), ``doc`` one line for progress and listings.
    """

    name: str
    run: Callable[[dict[str, Any]], Mapping[str, Any]]
    needs: tuple[str, ...] = ()
    gives: tuple[str, ...] = ()
    doc: str = ""
    skip: Callable[[dict[str, Any]], bool] | None = field(default=None, compare=False)

    def __call__(self, state: dict[str, Any]) -> dict[str, Any]:
        """Run this stage alone on ``state`` (updated in place and returned)."""
        missing = [k for k in self.needs if k not in state]
        if missing:
            raise KeyError(f"stage {self.name!r} needs {', '.join(missing)}, which no earlier "
                           "stage gave")
        out = dict(self.run(state) or {})
        lacking = [k for k in self.gives if k not in out]
        if lacking:
            raise KeyError(f"stage {self.name!r} did not give {', '.join(lacking)}")
        state.update(out)
        return state


def stage(name: str, needs: Iterable[str] = (), gives: Iterable[str] = (), doc: str = "",
          skip: Callable[[dict[str, Any]], bool] | None = None
          ) -> Callable[[Callable[[dict[str, Any]], Mapping[str, Any]]], Stage]:
    """Decorator: the function ``run(state) -> dict`` as a :class:`Stage` named ``name``."""
    def wrap(fn: Callable[[dict[str, Any]], Mapping[str, Any]]) -> Stage:
        first = (fn.__doc__ or "").strip().splitlines()
        return Stage(name, fn, tuple(needs), tuple(gives), doc or (first[0] if first else ""),
                     skip)
    return wrap


def run_stages(stages: Iterable[Stage], state: dict[str, Any],
               timings: dict[str, float] | None = None, until: str | None = None
               ) -> dict[str, Any]:
    """Run ``stages`` in order over ``state`` (in place; returned); each stage's wall time in
    seconds goes to ``timings[stage.name]``; a stage whose ``skip(state)`` is true is passed
    over (no timing). ``until``: stop after the stage of that name."""
    stages = tuple(stages)
    names = stage_names(stages)
    if until is not None and until not in names:
        raise KeyError(f"no stage {until!r}; the stages are {', '.join(names)}")
    for s in stages:
        if s.skip is not None and s.skip(state):
            if s.name == until:
                break
            continue
        t0 = time.perf_counter()
        s(state)
        if timings is not None:
            timings[s.name] = timings.get(s.name, 0.0) + time.perf_counter() - t0
        if s.name == until:
            break
    return state


def stage_names(stages: Iterable[Stage]) -> list[str]:
    """The names of ``stages`` in order."""
    return [s.name for s in stages]
