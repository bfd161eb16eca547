"""Worlds: edits saved durably, undo and redo, damaged files refused."""

import os
import signal
import subprocess
import sys

import numpy as np
import pytest

import pmc


def test_an_edit_digs_and_undo_redo_move_through_it(tmp_path):
    path = tmp_path / "w.pmcw"
    with pmc.World.create(path, pmc.Planet("earthlike", 7)) as w:
        before = w.planet.surface_height(10.0, 20.0)
        edit = w.edit("remove", 10.0, 20.0, 20.0)
        assert edit >= 1
        dug = w.planet.surface_height(10.0, 20.0)
        assert dug < before - 10.0
        assert w.planet.info()["edits"] == 1
        assert [e["brush"] for e in w.edits()] == ["remove"]
        assert w.undo() == edit
        assert w.planet.surface_height(10.0, 20.0) == before
        assert w.undo() is None
        assert w.redo() == edit
        assert w.planet.surface_height(10.0, 20.0) == dug
        w.edit("paint", 10.0, 20.1, 15.0, material=0)
    again = pmc.Planet.open_world(path)
    assert len(again.edits()) == 2
    assert again.planet.surface_height(10.0, 20.0) == dug
    again.close()


def test_an_acknowledged_edit_survives_a_kill(tmp_path):
    path = tmp_path / "killed.pmcw"
    pmc.World.create(path, pmc.Planet("moon", 3)).close()
    child = (
        "import os, signal, sys, pmc\n"
        f"w = pmc.World.open({str(path)!r})\n"
        "w.edit('add', 1.0, 2.0, 12.0)\n"
        "print('acknowledged', flush=True)\n"
        "os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    run = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True)
    assert run.returncode == -signal.SIGKILL and "acknowledged" in run.stdout
    with pmc.World.open(path) as w:
        assert [e["brush"] for e in w.edits()] == ["add"]


def test_bad_edits_are_refused_and_change_nothing(tmp_path):
    with pmc.World.create(tmp_path / "w.pmcw", pmc.Planet("moon", 3)) as w:
        for call, pattern in [
            (lambda: w.edit("explode", 0.0, 0.0, 5.0), "unknown brush"),
            (lambda: w.edit("paint", 0.0, 0.0, 5.0), "material"),
            (lambda: w.edit("paint", 0.0, 0.0, 5.0, material="cheese"), "unknown material"),
            (lambda: w.edit("add", 0.0, 0.0, 5.0, material=1), "paint brush only"),
            (lambda: w.edit("add", 95.0, 0.0, 5.0), "latitude"),
            (lambda: w.edit("add", 0.0, 0.0, -5.0), "radius"),
            (lambda: w.edit("add", 0.0, 0.0, 5.0, alt=float("inf")), "finite"),
        ]:
            with pytest.raises(pmc.PmcError, match=pattern):
                call()
        assert w.edits() == []


def test_damaged_and_foreign_files_are_refused_by_name(tmp_path):
    foreign = tmp_path / "notes.pmcw"
    foreign.write_bytes(b"these are not the droids" * 100)
    with pytest.raises(pmc.PmcError, match="notes.pmcw"):
        pmc.World.open(foreign)
    good = tmp_path / "good.pmcw"
    with pmc.World.create(good, pmc.Planet("moon", 3)) as w:
        w.edit("add", 1.0, 2.0, 12.0)
    data = bytearray(good.read_bytes())
    data[0:16] = b"x" * 16  # the SQLite header
    bad = tmp_path / "bad.pmcw"
    bad.write_bytes(bytes(data))
    with pytest.raises(pmc.PmcError, match="bad.pmcw"):
        pmc.World.open(bad)
    with pytest.raises(pmc.PmcError, match="exists"):
        pmc.World.create(good, pmc.Planet("moon", 3))
    # The good world is untouched by it all.
    with pmc.World.open(good) as w:
        assert len(w.edits()) == 1
