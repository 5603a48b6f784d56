"""grammar search on Ray: the same evaluations and result as the local process pool.

One local Ray cluster of 2 CPUs serves the whole module (starting one takes seconds).
The tests skip with a reason when ray is not installed, unless ROBOTWRIGHT_REQUIRE_RAY
is set (CI sets it: there they fail instead).
"""

from __future__ import annotations

import importlib.util
import os
import sys

import pytest

from robotwright.cli import main
from robotwright.grammar.loader import default_grammar
from robotwright.grammar.objectives import NoSelfCollision, Payload, Reach
from robotwright.grammar.search import beam_search, mcts_search, random_search

HAVE_RAY = importlib.util.find_spec("ray") is not None
needs_ray = pytest.mark.skipif(
    not HAVE_RAY and not os.environ.get("ROBOTWRIGHT_REQUIRE_RAY"),
    reason="needs ray (pip install 'robotwright[ray]')",
)


@pytest.fixture(scope="module")
def cluster():
    from robotwright.grammar.executors import RayExecutor

    ex = RayExecutor(num_cpus=2)
    yield ex
    ex.shutdown()
    import ray

    assert not ray.is_initialized()  # the cluster it started is stopped


def _key(res):
    return [(e.design.hash(), e.values, e.violations, e.score) for e in res.evaluations]


@needs_ray
@pytest.mark.parametrize(
    ("search", "kw"),
    [
        (beam_search, dict(beam_width=3)),
        (mcts_search, dict()),
        (random_search, dict()),
    ],
)
def test_ray_evaluates_as_the_local_pool(cluster, search, kw):
    g = default_grammar()
    args = (g, [Reach()], [NoSelfCollision()])
    common = dict(budget=30, max_links=3, seed=5, workers=2, **kw)
    local = search(*args, **common)
    on_ray = search(*args, executor=cluster, **common)
    assert local.n_evaluated == 30
    assert _key(on_ray) == _key(local)
    assert on_ray.best == local.best


@needs_ray
def test_ray_physics_objective_as_local(cluster):
    g = default_grammar()
    args = (g, [Payload(samples=4)], [NoSelfCollision()])
    common = dict(budget=8, max_links=2, seed=1, workers=2)
    local = random_search(*args, **common)
    assert _key(random_search(*args, executor=cluster, **common)) == _key(local)


@needs_ray
def test_ray_batches_tasks_in_order(cluster):
    # Results come back in submission order whatever the batch size.
    items = list(range(23))
    for chunk in (1, 4, 23, 50):
        assert list(cluster.map(abs, [-i for i in items], chunksize=chunk)) == items
    assert cluster.workers == 2


@needs_ray
def test_cli_ray_writes_the_same_log_and_result(cluster, tmp_path, capsys):
    # Ray already runs in this process (the module's cluster): --ray uses it as it is.
    argv = ["grammar", "search", "--budget", "12", "--max-links", "2", "--objective", "reach"]
    assert main([*argv, "--workers", "2", "--log", str(tmp_path / "local.jsonl")]) == 0
    local = capsys.readouterr().out
    assert main([*argv, "--workers", "2", "--ray", "--log", str(tmp_path / "ray.jsonl")]) == 0
    on_ray = capsys.readouterr().out
    # the first line holds the time taken
    assert on_ray.splitlines()[1:] == local.splitlines()[1:]
    assert (tmp_path / "ray.jsonl").read_bytes() == (tmp_path / "local.jsonl").read_bytes()
    assert len((tmp_path / "ray.jsonl").read_text().splitlines()) == 1 + 12
    import ray

    assert ray.is_initialized()  # a cluster it did not start is left running


@pytest.mark.parametrize(
    "address", ["bogus", "http://h:1", "ray://", "ray://host", "host", "auto; rm", "ray://h:1/x"]
)
def test_cli_ray_address_forms_refused(capsys, address):
    code = main(["grammar", "search", "--budget", "2", "--max-links", "1", "--ray", address])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("error: --ray:") and "expected 'auto'" in err and err.count("\n") == 1


@pytest.mark.parametrize("address", ["auto", "ray://head:10001", "10.0.0.2:6379", "[::1]:6379"])
def test_ray_address_forms_accepted(address):
    from robotwright.grammar.executors import check_ray_address

    assert check_ray_address(address) == address


def test_cli_workers_with_a_joined_cluster_refused(capsys):
    argv = ["grammar", "search", "--budget", "2", "--max-links", "1"]
    assert main([*argv, "--ray", "auto", "--workers", "2"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --workers:") and err.count("\n") == 1


def test_without_ray_the_error_says_how_to_install(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray raises ImportError
    from robotwright.grammar.executors import RayExecutor

    with pytest.raises(ImportError, match=r"robotwright\[ray\]"):
        RayExecutor()
    log = tmp_path / "log.jsonl"
    argv = ["grammar", "search", "--budget", "2", "--max-links", "1", "--ray"]
    assert main([*argv, "--log", str(log)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --ray:") and "robotwright[ray]" in err
    assert err.count("\n") == 1
    assert not log.exists()  # refused before any output
