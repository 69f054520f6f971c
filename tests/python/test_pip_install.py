"""`pip install .` from the checkout works offline and installs the same module (issue 32).

pip runs in a fresh virtual environment (Debian's python3-venv, with the system's numpy) with
--no-index, so nothing can be downloaded; setup.py reuses this build tree (AEROCAL_BUILD_DIR).
"""

import os
import subprocess
import sys

import aerocal


def test_pip_install_dot_offline_into_a_venv(tmp_path):
    source = os.environ["AEROCAL_SOURCE_DIR"]
    build = os.path.dirname(os.path.dirname(aerocal.__file__))  # <build>/python/aerocal
    build = os.path.dirname(build)
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(AEROCAL_BUILD_DIR=build, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    python = str(venv / "bin" / "python")
    done = subprocess.run([python, "-m", "pip", "install", "--no-index", source],
                          capture_output=True, text=True, env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    probe = ("import aerocal, json; print(json.dumps([aerocal.__file__, aerocal.models(), "
             "aerocal.formats()]))")
    done = subprocess.run([python, "-c", probe], capture_output=True, text=True, env=env,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    import json
    where, models, formats = json.loads(done.stdout)
    assert where.startswith(str(venv)), where  # the installed copy, not the build tree's
    assert models == aerocal.models() and formats == aerocal.formats()
    assert os.path.exists(os.path.join(os.path.dirname(where), "__init__.pyi"))
