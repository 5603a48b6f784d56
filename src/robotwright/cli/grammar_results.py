"""What ``robotwright grammar search`` prints after its search: the refine of the best
design's continuous parameters (``--refine``), the Pareto front (``--pareto``), and
objective values with their units."""

from __future__ import annotations

import argparse

from robotwright._progress import working


def value_text(objective: object, value: float) -> str:
    """``name = value unit``, saying when the value is the objective's bound."""
    from robotwright.grammar.winners import UNITS

    name = getattr(objective, "name", "")
    unit = UNITS.get(name, "")
    text = f"{name} = {value:.6g} {unit}".rstrip()
    limit = getattr(objective, "limit", None)
    if limit is not None and value >= limit:
        bound = f"{limit:g} {unit}".rstrip()
        text += f" (the {bound} bound: the design holds at least this)"
    return text


def refine_best(
    args: argparse.Namespace, g, res, objectives, constraints, executor, progress
) -> str:  # noqa: ANN001
    """CMA-ES over the best design's continuous parameters; its evaluations join the
    search's, so the winners and the best include them. Returns the line to print."""
    from robotwright.grammar.refine import refine

    before = res.best
    searched = {e.design.hash(): e for e in res.evaluations}
    out = refine(
        g,
        before.design,
        objectives,
        constraints,
        budget=args.refine,
        seed=args.seed,
        executor=executor,
        workers=args.workers,
        force_workers=args.force_workers,
        # the search's log, appended to: a resumed run takes the refine's evaluations too
        log=args.log or args.resume,
        resume=args.resume,
        known=searched,
        progress=progress,
    )
    res.evaluations.extend(e for e in out.evaluations if e.design.hash() not in searched)
    if out.best.rank_key > before.rank_key:
        res.best = out.best
    first = objectives[0]
    restarts = (
        f", {out.restarts} restart(s) after all-infeasible generations" if out.restarts else ""
    )
    return (
        f"refined {len(out.parameters)} continuous parameter(s) of design "
        f"{before.design.hash()} over {len(out.evaluations)} designs (CMA-ES): "
        f"{value_text(first, before.values[first.name])} -> "
        f"{value_text(first, res.best.values[first.name])}\n"
        f"refine stopped: {out.stopped}{restarts}"
    )


def report_front(args: argparse.Namespace, g, res, objectives: list, task) -> int:  # noqa: ANN001
    """Print the Pareto front (values with units) and write it with -o (the pictures on
    ``task``'s carrier)."""
    from robotwright.grammar.objectives import pareto_front
    from robotwright.grammar.winners import UNITS, write_front

    front = pareto_front(res.evaluations, objectives)
    feasible = sum(e.feasible for e in res.evaluations)
    print(f"Pareto front: {len(front)} of {feasible} feasible designs")
    header = "  ".join(
        f"{o.name} [{UNITS[o.name]}]" if UNITS.get(o.name) else o.name for o in objectives
    )
    print(f"  #  {header}  design")
    for i, ev in enumerate(front, 1):
        cells = "  ".join(f"{ev.values[o.name]:.6g}" for o in objectives)
        print(f"{i:>3}  {cells}  {ev.design.hash()}")
    bounded = [o for o in objectives if getattr(o, "limit", None) is not None]
    for o in bounded:
        if any(ev.values[o.name] >= o.limit for ev in front):
            print(f"note: {value_text(o, o.limit)}")
    if args.out:
        from robotwright.render.api import draw_pose

        with working(f"writing the front to {args.out}"):
            folders = write_front(
                g,
                front,
                objectives,
                args.out,
                evaluated=res.evaluations,
                task=task,
                pictures=not args.no_picture,
                draw_carrier=draw_pose,
            )
        extra = "" if args.no_picture else ", pareto.png"
        print(f"written to {args.out}: {', '.join(f.name for f in folders)}, front.json{extra}")
    return 0
