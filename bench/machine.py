"""What the bench ran on: CPU, cores, memory, the flexcontact commit and the versions of the
libraries the cases actually loaded (resolved paths and, where dpkg knows them, packages)."""
from __future__ import annotations

import os
import subprocess
from pathlib import Path


def _first(path: str, key: str) -> str:
    try:
        for line in Path(path).read_text().splitlines():
            if line.startswith(key):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return ""


def _run(cmd: list[str], cwd=None) -> str:
    try:
        return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=30,
                              check=False).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        return ""


def commit(repo: Path) -> dict:
    """The flexcontact commit and whether the tree had uncommitted changes."""
    head = _run(["git", "rev-parse", "HEAD"], cwd=repo)
    dirty = _run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=repo)
    return {"commit": head, "dirty": bool(dirty)}


def package_of(path: str) -> str:
    """'package version' of the Debian package owning a file, or ''."""
    owner = _run(["dpkg", "-S", path]).split(":")[0]
    if not owner:
        return ""
    version = _run(["dpkg-query", "-W", "-f=${Version}", owner])
    return f"{owner} {version}".strip()


def machine() -> dict:
    mem_kb = _first("/proc/meminfo", "MemTotal").split()
    return {
        "cpu": _first("/proc/cpuinfo", "model name"),
        "cores": os.cpu_count(),
        "usable_cores": len(os.sched_getaffinity(0)),
        "memory_gb": round(int(mem_kb[0]) / 2**20, 1) if mem_kb else None,
        "load_average_at_start": list(os.getloadavg()),
    }


def libraries(paths: list[str]) -> list[dict]:
    """Each loaded library with the package that ships it."""
    return [{"path": p, "package": package_of(p)} for p in paths]
