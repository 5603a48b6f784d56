"""``robotwright grammar check|count|sample|search|export``."""

from __future__ import annotations

import argparse
import math
import random
import sys
import time
from pathlib import Path

from robotwright._atomic import atomic_dir, check_output_path
from robotwright._outputs import check_overwrite
from robotwright._progress import STEP_REPORT_S, Progress, working
from robotwright._progress import duration as _duration
from robotwright.cli.grammar_results import refine_best, report_front, value_text
from robotwright.cli.options import add_overwrite_flag
from robotwright.errors import GrammarError, InputFileError, Problem

#: Largest ``--max-links`` the commands accept. Exact counting grows with the cube of
#: the link count (bundled grammar: 50 links about 5 s, 100 links 40 s, 200 links
#: minutes), and a limb of more than 50 links is no supernumerary limb. The Python API
#: (robotwright.grammar.count, sample, ...) takes any size.
MAX_LINKS = 50
#: Work estimated to take longer than this [s] is announced with a warning first.
LONG_WORK_S = 60.0


def _int_at_least(low: int):
    """An argparse ``type`` for integers >= ``low`` (a usage error, exit 2, otherwise)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"expected an integer >= {low}, got {value}")
        return value

    parse.__name__ = f"integer >= {low}"
    return parse


def _max_links(text: str) -> int:
    """``--max-links``: an integer from 0 to :data:`MAX_LINKS` (usage error, exit 2)."""
    value = _int_at_least(0)(text)
    if value > MAX_LINKS:
        raise argparse.ArgumentTypeError(
            f"expected at most {MAX_LINKS} (the limit of --max-links: counting and sampling "
            f"grow with the cube of the link count), got {value}"
        )
    return value


_MAX_LINKS_HELP = f"largest number of links in a design (0 to {MAX_LINKS})"


def _warn_long(estimate_s: float, what: str) -> None:
    if estimate_s > LONG_WORK_S:
        print(
            f"warning: {what} will take about {_duration(estimate_s)} (estimated); "
            "progress follows, Ctrl-C stops",
            file=sys.stderr,
            flush=True,
        )


def _check_design_dir(out: Path, overwrite: bool, kind: str = "design") -> None:
    """Refuse an output that would replace something that is not a design folder.

    With ``--overwrite`` the design commands replace an earlier design folder (of
    ``kind``: one design, or the designs of ``grammar sample``); a file, or a non-empty
    folder robotwright did not write as such, is the user's data and is never replaced
    (:func:`robotwright._outputs.check_folder_output`).
    """
    check_output_path(out, folder=True)
    if out.exists() and not out.is_dir():
        raise GrammarError([Problem(str(out), "is a file; expected a folder for the design")])
    check_overwrite(out, overwrite, kind=kind)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "grammar",
        help="generate robot limbs (SRLs) from a graph grammar",
        description="Check grammars, count, enumerate, sample and search limb designs, "
        "show and export them. Without --grammar/--library the bundled SRL grammar and "
        "component library are used.",
    )
    gsub = p.add_subparsers(dest="grammar_command", metavar="ACTION", required=True)

    def common(q: argparse.ArgumentParser) -> None:
        q.add_argument(
            "--grammar", type=Path, default=None, help="grammar YAML (default: bundled SRL grammar)"
        )
        q.add_argument(
            "--library",
            type=Path,
            default=None,
            help="component library YAML (default: the grammar's, else the bundled library)",
        )

    def seed(q: argparse.ArgumentParser, what: str) -> None:
        q.add_argument(
            "--seed",
            type=int,
            default=0,
            help=f"random seed: the same seed gives the same {what} (default 0)",
        )

    q = gsub.add_parser(
        "check",
        help="validate a grammar file and summarise it",
        description="Load a grammar YAML (and its component library), print every problem "
        "found, or its symbols, rules and the number of designs of 0 to 3 links.",
    )
    q.add_argument("file", type=Path, help="grammar YAML")
    q.add_argument("--library", type=Path, default=None, help="component library YAML")
    q.set_defaults(func=_check)

    q = gsub.add_parser(
        "count",
        help="exact number of designs up to a size",
        description="Count the designs with at most --max-links links exactly (total and "
        "per link count); --enumerate also generates each one and reports the rate.",
    )
    common(q)
    q.add_argument("--max-links", type=_max_links, required=True, help=_MAX_LINKS_HELP)
    q.add_argument(
        "--enumerate",
        action="store_true",
        help="also enumerate every design and check the count (slow beyond 4 links: "
        "progress and an estimate are printed)",
    )
    q.set_defaults(func=_count)

    q = gsub.add_parser(
        "sample",
        help="draw designs uniformly and write their files",
        description="Draw -n designs uniformly at random among those with at most "
        "--max-links links; write each one's MJCF, URDF, design text/JSON, tree and picture "
        "into OUT/<number>_<hash>/.",
    )
    common(q)
    seed(q, "designs")
    q.add_argument(
        "-n", type=_int_at_least(1), default=1, help="number of designs to draw (default 1)"
    )
    q.add_argument("--max-links", type=_max_links, default=4, help=f"{_MAX_LINKS_HELP}; default 4")
    q.add_argument("-o", "--out", type=Path, required=True, help="output folder")
    q.add_argument("--no-picture", action="store_true", help="skip the PNG pictures")
    add_overwrite_flag(q)
    q.set_defaults(func=_sample)

    q = gsub.add_parser(
        "search",
        help="search designs for an objective",
        description="Search the designs with at most --max-links links for the best value "
        "of an objective under constraints; print the best design (and write its files "
        "with -o).",
    )
    common(q)
    q.add_argument(
        "--objective",
        action="append",
        default=None,
        choices=_OBJECTIVE_NAMES,
        help="reach: farthest end point [m] (default); workspace: reachable volume "
        "estimate [m^3]; coverage: share of a given box (0.2-0.6 m, +-0.2 m, 0.2-0.6 m "
        "in the mount frame, 5 cm cells) the tool reaches; mass: lightest [kg]; dof: most joints; worn by the carrier "
        "(mini_humanoid's back): payload: heaviest load held at every sampled pose [kg]; "
        "track: smallest RMS error following a circle and a line [m]; energy: least mean "
        "mechanical power on that path [W]. Repeatable: the first scores a design and the "
        "second breaks ties (one objective alone: ties broken by --tie-break); with "
        "--weights their weighted sum scores; with --pareto all of them make the front",
    )
    q.add_argument(
        "--tie-break",
        default="mass",
        choices=[*_OBJECTIVE_NAMES, "none"],
        help="with one --objective: the objective that orders designs of equal value, e.g. "
        "two limbs both at payload's bound (default mass: the lighter first; none: the "
        "first evaluated)",
    )
    q.add_argument(
        "--weights",
        type=_weights,
        default=None,
        metavar="W,W,...",
        help="score by the weighted sum of the --objective values, one weight each, every "
        "value oriented so that larger is better (a minimised one enters negated); the "
        "weights carry the units' exchange rate (e.g. payload,mass with 1,2: 1 kg of limb "
        "is worth 2 kg of payload)",
    )
    q.add_argument(
        "--pareto",
        action="store_true",
        help="report the Pareto front of the --objective values (two or more) over every "
        "design evaluated: the feasible designs no other beats in every objective; -o "
        "writes front_1 ... and pareto.png. beam and mcts steer by the first objective, "
        "random samples evenly",
    )
    q.add_argument(
        "--refine",
        type=_int_at_least(2),
        default=None,
        metavar="N",
        help="then search the best design's continuous parameters (link lengths, strokes, "
        "joint limits ...) anywhere within their ranges by CMA-ES over N designs, "
        "keeping its structure; logged to --log and taken from --resume as the search's "
        "(pip install 'robotwright[cma]'; not with --pareto)",
    )
    q.add_argument(
        "--task",
        type=Path,
        default=None,
        metavar="FILE",
        help="a task YAML: the carrier and where the limb is worn, the payload test, the "
        "path to track, the collision check (see docs/grammar.md); default: the built-in "
        "task (mini_humanoid's back, the circle and line)",
    )
    q.add_argument(
        "--constraint",
        action="append",
        default=None,
        help="no-self-collision and no-overlap (default; with no-carrier-collision for "
        "payload, track and energy, no-contact-on-track and within-ratings for track "
        "and energy, and max-track-error=0.01 for energy), no-carrier-collision, "
        "no-contact-on-track, within-ratings, joint-limits, max-mass=KG, "
        "max-track-error=M, max-dof=N, min-dof=N; repeatable",
    )
    q.add_argument(
        "--budget",
        type=_int_at_least(1),
        default=100,
        help="number of designs to evaluate (default 100)",
    )
    q.add_argument(
        "--method",
        default="beam",
        choices=["beam", "mcts", "random", "learned"],
        help="beam search (default), Monte Carlo tree search, uniform random sampling, or "
        "the learned search (a value network over partial designs, trained as it goes)",
    )
    q.add_argument(
        "--guided",
        action="store_true",
        help="beam and mcts: a value network over partial designs, trained on the "
        "evaluations so far, picks the expansions to try (what --method learned uses)",
    )
    q.add_argument(
        "--beam-width",
        type=_int_at_least(1),
        default=4,
        help="beam: partial designs kept per step (default 4)",
    )
    q.add_argument(
        "--batch",
        type=_int_at_least(1),
        default=None,
        help="mcts: leaves picked per round (default 8). A parameter of the search, not the "
        "worker count: the same seed gives the same search with any --workers or --ray; a "
        "log resumes only with the batch it was written with",
    )
    q.add_argument("--max-links", type=_max_links, default=4, help=f"{_MAX_LINKS_HELP}; default 4")
    seed(q, "search")
    q.add_argument(
        "--workers",
        type=_int_at_least(1),
        default=None,
        help="worker processes (default: CPU count; at most the CPU count unless "
        "--force-workers is given)",
    )
    q.add_argument(
        "--force-workers",
        action="store_true",
        help="allow --workers above the CPU count (each worker is a process started at once)",
    )
    q.add_argument(
        "--ray",
        nargs="?",
        const="",
        default=None,
        metavar="ADDRESS",
        help="evaluate on Ray workers (pip install 'robotwright[ray]'): alone, a local Ray "
        "cluster of --workers CPUs (default: the CPU count; not capped); 'auto', "
        "'ray://HOST:PORT' or 'HOST:PORT' joins a running cluster. Same result as without",
    )
    q.add_argument(
        "--log",
        type=Path,
        default=None,
        metavar="FILE",
        help="write one JSON line per evaluated design to FILE as it comes (design, "
        "objective values, constraint violations, seed, iteration)",
    )
    q.add_argument(
        "--resume",
        type=Path,
        default=None,
        metavar="FILE",
        help="take the evaluations of a log written by --log instead of repeating them, "
        "and append the new ones to it (or to --log FILE); same result as an "
        "uninterrupted search with the same seed",
    )
    q.add_argument(
        "-o",
        "--out",
        type=Path,
        default=None,
        help="write the best designs here: OUT/best_1 ... (design folders with their values, "
        "a picture on the carrier, and for track/energy the tool path against the reference)",
    )
    q.add_argument(
        "--top",
        type=_int_at_least(1),
        default=3,
        help="how many of the best designs -o writes (default 3)",
    )
    q.add_argument("--no-picture", action="store_true", help="with -o: skip the PNG pictures")
    add_overwrite_flag(q)
    q.set_defaults(func=_search)

    q = gsub.add_parser(
        "show",
        help="print a design: steps, tree, DH table per branch",
        description="Print a design's derivation steps, its tree, its DoF and mass, and a "
        "modified-DH table (Craig) per branch; --dot prints the tree as Graphviz DOT.",
    )
    common(q)
    q.add_argument(
        "design", type=Path, help="design file (design.txt or design.json) or design folder"
    )
    q.add_argument("--dot", action="store_true", help="print the design tree as Graphviz DOT only")
    q.set_defaults(func=_show)

    q = gsub.add_parser(
        "export",
        help="write the files of a design given as text or JSON",
        description="Build a design (design.txt or design.json, as sample and search write) "
        "and write its MJCF, URDF, design text/JSON, tree and picture into a folder.",
    )
    common(q)
    q.add_argument(
        "design", type=Path, help="design file (design.txt or design.json) or design folder"
    )
    q.add_argument("-o", "--out", type=Path, required=True, help="output folder")
    add_overwrite_flag(q)
    q.set_defaults(func=_export)


def _grammar(args: argparse.Namespace):
    from robotwright.grammar.loader import default_grammar, default_grammar_path, load_grammar

    if args.grammar is None and args.library is None:
        return default_grammar()
    return load_grammar(args.grammar or default_grammar_path(), args.library)


def _check(args: argparse.Namespace) -> int:
    from robotwright.grammar.derive import count_by_links
    from robotwright.grammar.loader import load_grammar

    try:
        g = load_grammar(args.file, args.library)
    except GrammarError as exc:
        for p in exc.problems:
            print(f"{p.severity}: {p}")
        print(f"{args.file}: {sum(p.severity == 'error' for p in exc.problems)} error(s)")
        return 1
    print(f"grammar {g.name} ({g.source}), library {g.library.name} ({g.library.source})")
    for s in g.symbols.values():
        comps = [c.name for c in g.library.for_symbol(s.name)]
        print(f"  symbol {s.name:3s} {s.kind:12s} {s.description}  components: {comps or '-'}")
    for r in g.rules.values():
        print(f"  {r}{'  (branching)' if r.branching else ''}")
    try:
        print(f"  designs by number of links 0..3: {count_by_links(g, 3)}")
    except GrammarError as exc:
        # Infinitely many designs of one link count: count, sample and search cannot
        # work with it (--max-links bounds links only), so the grammar is not valid.
        for p in exc.problems:
            print(f"{p.severity}: {p}")
        print(f"{args.file}: {sum(p.severity == 'error' for p in exc.problems)} error(s)")
        return 1
    print(f"{args.file}: valid")
    return 0


def _count(args: argparse.Namespace) -> int:
    from robotwright.grammar.derive import count, count_by_links, enumerate_designs

    g = _grammar(args)
    total = count(g, args.max_links)
    print(f"designs with at most {args.max_links} link(s): {total}", flush=True)
    print(f"by number of links: {count_by_links(g, args.max_links)}", flush=True)
    if args.enumerate:
        t0 = time.perf_counter()
        progress = Progress(total, "designs enumerated")
        calibrate = min(total, 2000)  # the rate of the first designs sets the estimate
        n = 0
        for _ in enumerate_designs(g, args.max_links):
            n += 1
            if n == calibrate:
                left = progress.eta(n)
                _warn_long(left or 0.0, f"enumerating {total} designs")
            if not n % 1000:
                progress.update(n)
        dt = max(time.perf_counter() - t0, 1e-9)
        print(
            f"enumerated: {n} in {dt:.2f} s ({n / dt:.0f} designs/s); equal to count: {n == total}"
        )
        return 0 if n == total else 1
    return 0


def _sample(args: argparse.Namespace) -> int:
    from robotwright.grammar.derive import Counter, sample
    from robotwright.grammar.export import export_design

    g = _grammar(args)
    rng = random.Random(args.seed)
    counter = Counter(g)
    check_output_path(args.out, folder=True)
    if args.out.exists() and not args.out.is_dir():
        raise GrammarError([Problem(str(args.out), "is a file; expected a folder for the designs")])
    check_overwrite(args.out, args.overwrite, kind="designs")
    progress = Progress(args.n, "designs written")
    # All or nothing: the designs are written into a temporary folder that becomes
    # args.out at the end (a full disk or Ctrl-C leaves the old output, or none).
    written = []
    with atomic_dir(args.out, kind="designs") as tmp:
        for k in range(args.n):
            d = sample(g, args.max_links, rng, counter)
            name = f"{k:03d}_{d.hash()}"
            export_design(g, d, tmp / name, picture=not args.no_picture, overwrite=True)
            written.append(f"{args.out / name}: {d}")
            if k == 0:
                _warn_long((progress.eta(1) or 0.0), f"writing {args.n} designs")
            progress.update(k + 1)
    # Announced once they exist: a reader that stops early (| head -1) takes nothing away.
    for line in written:
        print(line, flush=True)
    return 0


def _search_progress(budget: int, name: str):
    """A callback printing ``evaluated/budget, best, time left`` to stderr every 2 s at
    most, with a warning once the first evaluations show the search will take long."""
    progress = Progress(budget, "designs evaluated", every=STEP_REPORT_S)
    warned = [False]

    def show(n: int, best) -> None:
        if not warned[0] and n >= min(budget, 8):
            warned[0] = True
            _warn_long(progress.eta(n) or 0.0, f"evaluating {budget} designs")
        score = "-" if best is None else f"{best.values[name]:.4f}"
        progress.update(n, f", best {name} {score}")

    return show


#: Objectives that evaluate the limb worn by its carrier: their searches refuse designs
#: that touch the carrier unless --constraint says otherwise.
_CARRIER_OBJECTIVES = ("payload", "track", "energy")


#: The RMS tracking error (m) an ``energy`` search allows by default: a fifth of the
#: built-in circle's radius.
ENERGY_TRACK_ERROR = 0.01


def _default_constraints(args: argparse.Namespace) -> list[str]:
    asked = set(args.objective or ())
    out = ["no-self-collision", "no-overlap"]
    if asked & set(_CARRIER_OBJECTIVES):
        out.append("no-carrier-collision")
    if asked & {"track", "energy"}:
        out += ["no-contact-on-track", "within-ratings"]
    if "energy" in asked:  # the power of a limb that does the job, not of one that idles
        out.append(f"max-track-error={ENERGY_TRACK_ERROR:g}")
    return out


_OBJECTIVE_NAMES = [
    "reach",
    "workspace",
    "coverage",
    "mass",
    "dof",
    "payload",
    "track",
    "energy",
]


def _weights(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if not values or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(
            f"expected finite numbers separated by commas, e.g. 1,2; got {text!r}"
        )
    return values


def _objectives(args: argparse.Namespace, task) -> tuple[list, list] | str:  # noqa: ANN001
    """(objectives the search evaluates, in order: the scoring one first, the tie-break
    second; the objectives the user named), set for ``task``, or the error message."""
    from robotwright.grammar.objectives import WeightedSum

    names = args.objective or ["reach"]
    if len(set(names)) != len(names):
        return f"--objective: {', '.join(names)} names one twice; expected each once"
    named = [task.objective(n) for n in names]
    if args.pareto:
        if len(named) < 2 or args.weights is not None:
            return "--pareto: expected two --objective or more, and no --weights"
        return named, named
    if args.weights is not None:
        if len(args.weights) != len(named) or len(named) < 2:
            return (
                f"--weights: {len(args.weights)} weight(s) for {len(named)} objective(s); "
                "expected one per --objective, two objectives or more"
            )
        return [WeightedSum(tuple(named), args.weights), *named], named
    if len(named) == 1 and args.tie_break not in ("none", names[0]):
        return [*named, task.objective(args.tie_break)], named
    return named, named


def _search(args: argparse.Namespace) -> int:
    from robotwright.grammar.search import beam_search, check_workers, mcts_search, random_search
    from robotwright.grammar.task import DEFAULT_TASK, load_task

    g = _grammar(args)
    task = load_task(args.task) if args.task is not None else DEFAULT_TASK
    chosen = _objectives(args, task)
    if isinstance(chosen, str):
        print(f"error: {chosen}", file=sys.stderr)
        return 2
    objectives, named = chosen
    if args.out:
        _check_design_dir(args.out, args.overwrite, kind="designs")
    try:
        constraints = [task.constraint(c) for c in (args.constraint or _default_constraints(args))]
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.ray is None:
        try:
            check_workers(args.workers, args.force_workers, "--force-workers")
        except ValueError as exc:
            print(f"error: --workers: {exc}", file=sys.stderr)
            return 2
    elif args.ray and args.workers is not None:
        print(
            "error: --workers: a Ray cluster joined (--ray ADDRESS) has the workers it has; "
            "expected --workers only with --ray alone (a local cluster)",
            file=sys.stderr,
        )
        return 2
    if args.refine is not None and args.pareto:
        print("error: --refine: refines the best design of one score, not a front", file=sys.stderr)
        return 2
    if args.refine is not None:
        from robotwright.grammar.refine import _cma

        try:
            _cma()
        except ImportError as exc:
            print(f"error: --refine: {exc}", file=sys.stderr)
            return 2
    if args.guided and args.method not in ("beam", "mcts"):
        message = f"error: --guided: applies to --method beam or mcts, not {args.method}"
        print(message, file=sys.stderr)
        return 2
    if args.batch is not None and args.method != "mcts":
        print(f"error: --batch: applies to --method mcts, not {args.method}", file=sys.stderr)
        return 2
    _check_log_paths(args)
    if args.ray is not None:
        from robotwright.grammar.executors import check_ray_address, import_ray

        try:
            if args.ray:
                check_ray_address(args.ray)
            import_ray()
        except (ValueError, ImportError) as exc:
            print(f"error: --ray: {exc}", file=sys.stderr)
            return 2
    objective = objectives[0]
    t0 = time.perf_counter()
    kw = dict(
        budget=args.budget,
        max_links=args.max_links,
        seed=args.seed,
        workers=args.workers,
        force_workers=args.force_workers,
        progress=_search_progress(args.budget, objective.name),
    )
    kw.update(log=args.log, resume=args.resume)
    with _ray_executor(args) as executor:
        kw.update(executor=executor)
        if args.method == "beam":
            res = beam_search(
                g, objectives, constraints, beam_width=args.beam_width, guided=args.guided, **kw
            )
        elif args.method == "mcts":
            from robotwright.grammar.search import MCTS_BATCH

            batch = args.batch or MCTS_BATCH
            res = mcts_search(g, objectives, constraints, batch=batch, guided=args.guided, **kw)
        elif args.method == "learned":
            from robotwright.grammar.learned import learned_search

            res = learned_search(g, objectives, constraints, **kw)
        else:
            res = random_search(g, objectives, constraints, **kw)
        refined = ""
        searched = res.n_evaluated
        if args.refine is not None and res.best is not None:
            refined = refine_best(
                args,
                g,
                res,
                objectives,
                constraints,
                executor,
                _search_progress(args.refine, objective.name),
            )
    dt = time.perf_counter() - t0
    by_refine = res.n_evaluated - searched
    also = f" + {by_refine} by the refine (CMA-ES)" if by_refine else ""
    print(
        f"{args.method} search: {searched} designs evaluated{also} in {dt:.1f} s "
        f"(stopped: {res.stopped})"
    )
    if refined:
        print(refined)
    if res.best is None:
        print("no feasible design found")
        return 1
    if args.pareto:
        return report_front(args, g, res, named, task)
    print(
        f"best {value_text(objective, res.best.values[objective.name])} (design {res.best.design.hash()})"
    )
    for other in objectives[1:]:
        print(f"  {value_text(other, res.best.values[other.name])}")
    print(res.best.design.to_text(), end="")
    if args.out:
        from robotwright.grammar.winners import write_winners
        from robotwright.render.api import draw_pose

        with working(f"writing the winners to {args.out}"):
            folders = write_winners(
                g,
                res.evaluations,
                objectives,
                args.out,
                k=args.top,
                task=task,
                pictures=not args.no_picture,
                draw_carrier=draw_pose,
            )
        print(f"written to {args.out}: {', '.join(f.name for f in folders)}")
    return 0


def _check_log_paths(args: argparse.Namespace) -> None:
    """Before any work: --resume must be a file; --log must not replace a file unless it
    is the log resumed (appended to) or --overwrite is given."""
    if args.resume is not None and not args.resume.is_file():
        what = "is not a file" if args.resume.exists() else "does not exist"
        raise InputFileError(args.resume, f"{what}; expected a log written by --log")
    if args.log is None:
        return
    check_output_path(args.log)
    if args.resume is not None and args.log.exists() and args.log.samefile(args.resume):
        return
    check_overwrite(args.log, args.overwrite)


def _ray_executor(args: argparse.Namespace):
    """A :class:`RayExecutor` for ``--ray`` (stopped at the end when it started a local
    cluster), else a context giving ``None`` (the local process pool)."""
    from contextlib import nullcontext

    if args.ray is None:
        return nullcontext(None)
    from robotwright.grammar.executors import RayExecutor

    try:
        if args.ray:
            return RayExecutor(address=args.ray)
        return RayExecutor(num_cpus=args.workers)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        # Ray's own words, on one line: the cluster could not be started or joined.
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputFileError("--ray", f"cannot start or join the Ray cluster: {first}") from None


def _read_design(path: Path):
    """The design in ``path``: a design.txt or design.json file, or a design folder as
    ``grammar sample``/``search``/``export`` write it (its design.txt)."""
    from robotwright._inputs import MAX_YAML_BYTES, read_text
    from robotwright.grammar.design import Design

    if path.is_dir() and (path / "design.txt").is_file():
        path = path / "design.txt"
    try:
        text = read_text(path, MAX_YAML_BYTES)
    except InputFileError as exc:
        raise GrammarError([Problem(str(path), f"cannot read design: it {exc.reason}")]) from exc
    except OSError as exc:
        raise GrammarError(
            [Problem(str(path), f"cannot read design: {exc.strerror or exc}")]
        ) from exc
    src = str(path)
    if text.lstrip().startswith("{"):
        return Design.from_json(text, src)
    return Design.from_text(text, src)


def _show(args: argparse.Namespace) -> int:
    from robotwright.grammar.build import build
    from robotwright.grammar.derive import replay
    from robotwright.grammar.design import to_dot

    g = _grammar(args)
    d = _read_design(args.design)
    tree = replay(g, d, str(args.design))
    if args.dot:
        print(to_dot(tree, d.hash()), end="")
        return 0
    limb = build(g, d)
    hrdf = limb.to_hrdf()
    print(d.to_text(), end="")
    print(f"{limb.dof} DoF, {hrdf.total_mass:.4f} kg, {len(limb.bodies)} bodies")
    for n in tree.walk():
        depth, p = 0, n.parent
        while p is not None:
            depth, p = depth + 1, p.parent
        print(f"{'  ' * depth}{n.label()}")
    for k, br in enumerate(limb.branches):
        # Every number at full precision (Python's shortest exact form): forward
        # kinematics from the printed table alone equals MuJoCo's.
        print(
            f"branch {k} -> site '{br.site}': modified DH (a_i-1 m, alpha_i-1 rad, d_i m, theta_i rad)"
        )
        print("  frame 0 in the mount frame (4x4, m):")
        for row in br.base_frame:
            print("    " + " ".join(repr(float(v)) for v in row))
        for r in br.rows:
            print(
                f"  {r.name:8s} {r.type:6s} a={r.a!r} alpha={r.alpha!r} d={r.d!r} theta={r.theta!r}"
            )
        print(f"  tool point in the last frame (4x4, m), site '{br.site}':")
        for row in br.tool:
            print("    " + " ".join(repr(float(v)) for v in row))
    return 0


def _export(args: argparse.Namespace) -> int:
    from robotwright.grammar.export import export_design

    g = _grammar(args)
    _check_design_dir(args.out, args.overwrite)
    d = _read_design(args.design)
    export_design(g, d, args.out, overwrite=True)
    print(f"{args.out}: {d.hash()}")
    return 0
