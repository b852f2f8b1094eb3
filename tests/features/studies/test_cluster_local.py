"""Local by default: every socket a study's Dask cluster listens on is on the loopback address
(a LocalCluster's dashboard binds every interface on 8787 unless told otherwise), and no
module starts a LocalCluster but through studies.cluster.local_cluster."""
import ast
from pathlib import Path

import psutil
from mbcontrol import defaults
from mbcontrol.studies.cluster import local_cluster

ROOT = Path(__file__).resolve().parents[3]


def _listening(pids: set[int]) -> list[str]:
    """host:port of every TCP socket the processes `pids` listen on."""
    found = []
    for pid in pids:
        try:
            conns = psutil.Process(pid).net_connections(kind="inet")
        except psutil.NoSuchProcess:
            continue
        found += [f"{c.laddr.ip}:{c.laddr.port}" for c in conns if c.status == psutil.CONN_LISTEN]
    return found


def test_a_local_cluster_listens_on_loopback_only():
    with local_cluster(1, silence_logs=40) as cluster:
        me = psutil.Process()
        pids = {me.pid} | {p.pid for p in me.children(recursive=True)}
        sockets = _listening(pids)
        # the scheduler, its web server, the worker and its nanny listen, at least
        assert len(sockets) >= 4, sockets
        assert all(s.startswith("127.0.0.1:") for s in sockets), sockets
        web = f"127.0.0.1:{cluster.scheduler.http_server.port}"
        assert web in sockets and not web.endswith(":8787")


def test_the_host_is_the_users_to_name(monkeypatch):
    monkeypatch.setenv("MBCONTROL_DASK_HOST", "localhost")
    assert defaults.get("dask.host") == "localhost"


def test_every_local_cluster_goes_through_the_one_helper():
    """A LocalCluster(...) call anywhere in the package but studies/cluster.py would bring back
    its defaults (a dashboard on every interface)."""
    offenders = []
    for folder in ("mbcontrol", "controllers", "models"):
        for path in (ROOT / folder).rglob("*.py"):
            if path.name == "cluster.py" and path.parent.name == "studies":
                continue
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.Call) and getattr(node.func, "id", getattr(
                        node.func, "attr", None)) == "LocalCluster":
                    offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert offenders == []
