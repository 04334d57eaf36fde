#!/bin/sh
# The filter "Vertex BRDF: export for the web" under headless meshlabserver writes the GLB that
# vbrdf-web-export writes from the same result and project, byte for byte, and both viewer pages.
#   filter_matches_tool.sh WRAPPER EXPORT_TOOL PROJECT_DIR WORK
# WRAPPER: <build>/meshlab_run/run_meshlabserver.sh; PROJECT_DIR: a sample project (copied, never
# changed) with fit.mlx; WORK: an empty or scratch folder.
set -eu
wrapper=$1 tool=$2 src=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
cp -r "$src" "$work/project"
p=$work/project
mkdir -p "$p/web" "$work/tool"
# The fit filter's script with the export appended (meshlabserver needs every parameter listed).
sed 's#</FilterScript>##' "$p/fit.mlx" > "$work/fit_and_export.mlx"
cat >> "$work/fit_and_export.mlx" <<'MLX'
 <filter name="Vertex BRDF: export for the web">
  <Param name="exportedResultPly" type="RichString" value=""/>
  <Param name="outputGlb" type="RichString" value="web/object.glb"/>
  <Param name="writeViewer" type="RichBool" value="true"/>
  <Param name="overwriteWebFiles" type="RichBool" value="true"/>
 </filter>
</FilterScript>
MLX
"$wrapper" -p "$p/project.mlp" -s "$work/fit_and_export.mlx" > "$work/meshlabserver.log" 2>&1 ||
  { echo "FAIL: meshlabserver (see $work/meshlabserver.log)"; exit 1; }
grep -q "Vertex BRDF: web export of" "$work/meshlabserver.log" ||
  { echo "FAIL: the filter logged no export (see $work/meshlabserver.log)"; exit 1; }
"$tool" "$p/project_brdf.ply" --project "$p/project.mlp" --out "$work/tool/object.glb" > "$work/tool.log" 2>&1 ||
  { echo "FAIL: vbrdf-web-export (see $work/tool.log)"; exit 1; }
for f in object.glb object.html object_hosted.html; do
  [ -s "$p/web/$f" ] || { echo "FAIL: the filter wrote no $f"; exit 1; }
done
cmp "$p/web/object.glb" "$work/tool/object.glb" || { echo "FAIL: the filter's GLB differs from vbrdf-web-export's"; exit 1; }
echo "ok: the filter's GLB is vbrdf-web-export's, byte for byte ($(wc -c < "$p/web/object.glb") bytes), with both pages"
