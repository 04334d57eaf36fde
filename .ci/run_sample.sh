#!/usr/bin/env bash
# Runs a sample project's fit.mlx through the build's headless meshlabserver, with the result
# redirected into OUT (the sample folder is left untouched). The quickstart's last step; also a
# ctest (quickstart_run_sample), so that the README's first command cannot silently break.
#   bash .ci/run_sample.sh BUILD_DIR SAMPLE_PROJECT_DIR OUT_DIR
set -euo pipefail
BUILD="$(cd "$1" && pwd)"
SAMPLE="$(cd "$2" && pwd)"
mkdir -p "$3"
OUT="$(cd "$3" && pwd)"
NAME="$(basename "$SAMPLE")"
RESULT="$OUT/${NAME}_brdf.ply"
rm -f "$RESULT" "$OUT/${NAME}_brdf_report.txt"
# The parameter's type is kept as the sample wrote it (paths are RichString fields, see
# docs/parameters.md#how-the-dialogs-behave).
sed "s|name=\"outputPly\" type=\"\([A-Za-z]*\)\" value=\"[^\"]*\"|name=\"outputPly\" type=\"\1\" value=\"$RESULT\"|" \
  "$SAMPLE/fit.mlx" > "$OUT/fit.mlx"
grep -q "value=\"$RESULT\"" "$OUT/fit.mlx" \
  || { echo "run_sample: could not redirect outputPly of $SAMPLE/fit.mlx into $OUT" >&2; exit 1; }
"$BUILD/meshlab_run/run_meshlabserver.sh" -p "$SAMPLE/project.mlp" -s "$OUT/fit.mlx" > "$OUT/meshlabserver.log" 2>&1 \
  || { tail -40 "$OUT/meshlabserver.log"; echo "meshlabserver failed: see $OUT/meshlabserver.log" >&2; exit 1; }
for f in "$RESULT" "$OUT/${NAME}_brdf_report.txt"; do
  [ -s "$f" ] || { tail -20 "$OUT/meshlabserver.log"; echo "run_sample: $f was not written" >&2; exit 1; }
done
grep "^Vertex BRDF: " "$OUT/meshlabserver.log" | grep -v "%)" || true
echo
cat "$OUT/${NAME}_brdf_report.txt"
echo
echo "Result: $RESULT (open it in MeshLab; per-vertex kd, ks, shininess, color_r/g/b, dq, sq, ...)"
