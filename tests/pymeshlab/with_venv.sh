#!/usr/bin/env bash
# with_venv.sh [--gl] PYTHON SCRIPT ARGS...: runs SCRIPT with the virtual environment's PYTHON, or
# reports the test as skipped (exit status 77) naming what is missing. --gl: with an OpenGL context
# for the plugin, as docs/pymeshlab.md#opengl tells users: VBRDF_OPENGL=1, Qt's platform plugins of
# the same Qt as the wheel's (PyQt5-Qt5 5.15.2 in the environment), under xvfb-run.
gl=0
if [ "$1" = --gl ]; then gl=1; shift; fi
python=$1
shift
if [ ! -x "$python" ]; then
  echo "SKIPPED: no PyMeshLab virtual environment at $python (.ci/setup-pymeshlab.sh makes it; it needs PyPI)"
  exit 77
fi
if [ $gl = 0 ]; then exec "$python" "$@"; fi
plugins="$("$python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")/PyQt5/Qt5/plugins"
if [ ! -d "$plugins/platforms" ]; then
  echo "SKIPPED: no Qt platform plugins in $python's environment (pip install PyQt5-Qt5==5.15.2; .ci/setup-pymeshlab.sh does)"
  exit 77
fi
if ! command -v xvfb-run >/dev/null; then
  echo "SKIPPED: xvfb-run missing (apt-get install xvfb xauth)"
  exit 77
fi
VBRDF_OPENGL=1 QT_PLUGIN_PATH="$plugins" exec xvfb-run -a "$python" "$@"
