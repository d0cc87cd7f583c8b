"""Package hygiene: pybullet is only loaded by the simulation modules; the lazy exports work."""

from __future__ import annotations

import subprocess
import sys

from alica import worldsim


def test_alica_skills_and_the_grid_do_not_load_pybullet() -> None:
    code = (
        "import sys, alica, alica.skills, alica.worldsim, alica.worldsim.grid, alica.worldsim.errors, alica.worldsim.geometry\n"
        "assert 'pybullet' not in sys.modules, 'pybullet was imported'\n"
        "alica.worldsim.World\n"
        "assert 'pybullet' in sys.modules\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr


def test_lazy_exports() -> None:
    from alica.worldsim.scenarios import lunar
    from alica.worldsim.world import World

    assert worldsim.World is World
    assert worldsim.lunar is lunar
    assert "blocks_facts" in dir(worldsim)


def test_importing_is_quiet() -> None:
    code = "import alica.worldsim.world as w\nw.World().add_robot('stummel', 's')\n"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout == "" and done.stderr == ""
