"""Self-tests of the e2e helpers (PLY I/O, colour metrics, .mlx/.mlp rewriting, output checks).
Run: python3 -m unittest -v test_e2e_lib (from tests/e2e)."""
import os
import tempfile
import unittest
import xml.etree.ElementTree as ET

import numpy as np

import check_output
import e2e_lib as lib

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLE_MLX = os.path.join(HERE, "..", "..", "sample_projects", "synth_basic", "fit.mlx")


def mesh_vertex(n, colour=False, extra=()):
    fields = [(c, "f4") for c in ("x", "y", "z", "nx", "ny", "nz")]
    if colour:
        fields += [(c, "u1") for c in ("red", "green", "blue", "alpha")]
    fields += [(name, "f4") for name in extra]
    v = np.zeros(n, fields)
    rng = np.random.default_rng(1)
    for c in ("x", "y", "z"):
        v[c] = rng.random(n)
    v["nz"] = 1
    return v


class PlyTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def test_binary_round_trip(self):
        v = mesh_vertex(5, colour=True, extra=("diffuse_r",))
        v["red"] = [0, 1, 2, 254, 255]
        v["diffuse_r"] = [0.5, 1.5, -2, 3e-7, 1e9]
        faces = np.array([[0, 1, 2], [2, 3, 4]])
        path = os.path.join(self.tmp.name, "a.ply")
        lib.write_ply(path, v, faces)
        ply = lib.read_ply(path)
        self.assertEqual(ply.property_names(), list(v.dtype.names))
        for name in v.dtype.names:
            np.testing.assert_array_equal(ply.vertex[name], v[name])
        np.testing.assert_array_equal(ply.faces, faces)

    def test_empty_mesh(self):
        path = os.path.join(self.tmp.name, "e.ply")
        lib.write_ply(path, mesh_vertex(0), np.zeros((0, 3), int))
        ply = lib.read_ply(path)
        self.assertEqual(len(ply.vertex), 0)
        self.assertEqual(ply.faces.shape, (0, 3))

    def test_ascii(self):
        path = os.path.join(self.tmp.name, "t.ply")
        with open(path, "w") as f:
            f.write("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property uchar red\nelement face 1\nproperty list uchar int vertex_indices\n"
                    "end_header\n0 0 10\n1 0.5 20\n0 1 30\n3 0 1 2\n")
        ply = lib.read_ply(path)
        np.testing.assert_allclose(ply.vertex["y"], [0, 0.5, 1])
        np.testing.assert_array_equal(ply.vertex["red"], [10, 20, 30])
        np.testing.assert_array_equal(ply.faces, [[0, 1, 2]])

    def test_truncated_file_is_rejected(self):
        path = os.path.join(self.tmp.name, "b.ply")
        lib.write_ply(path, mesh_vertex(4), np.array([[0, 1, 2]]))
        with open(path, "rb") as f:
            data = f.read()
        with open(path, "wb") as f:
            f.write(data[:-5])
        with self.assertRaises(ValueError):
            lib.read_ply(path)


class ColourTest(unittest.TestCase):
    # Sharma, Wu, Dalal (2005), "The CIEDE2000 color-difference formula", Table 1.
    PAIRS = [((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
             ((50.0, 3.1571, -77.2803), (50.0, 0.0, -82.7485), 2.8615),
             ((50.0, 0.0, 0.0), (50.0, -1.0, 2.0), 2.3669),
             ((50.0, 2.49, -0.001), (50.0, -2.49, 0.0009), 7.1792),
             ((50.0, -0.001, 2.49), (50.0, 0.0009, -2.49), 4.8045),
             ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
             ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644),
             ((22.7233, 20.0904, -46.694), (23.0331, 14.973, -42.5619), 2.0373),
             ((2.0776, 0.0795, -1.135), (0.9033, -0.0636, -0.5514), 0.9082)]

    def test_ciede2000_reference_pairs(self):
        lab1 = np.array([p[0] for p in self.PAIRS])
        lab2 = np.array([p[1] for p in self.PAIRS])
        np.testing.assert_allclose(lib.ciede2000(lab1, lab2), [p[2] for p in self.PAIRS], atol=1e-4)
        np.testing.assert_allclose(lib.ciede2000(lab2, lab1), [p[2] for p in self.PAIRS], atol=1e-4)

    def test_lab_of_white_and_black(self):
        np.testing.assert_allclose(lib.linear_rgb_to_lab([[1, 1, 1], [0, 0, 0]]), [[100, 0, 0], [0, 0, 0]], atol=1e-3)

    def test_srgb_round_trip(self):
        x = np.linspace(0, 1, 101)
        np.testing.assert_allclose(lib.srgb_to_linear(lib.linear_to_srgb(x)), x, atol=1e-12)

    def test_fits_remove_scale_and_colour_matrix(self):
        rng = np.random.default_rng(2)
        gt = rng.random((200, 3)) * 0.8 + 0.1
        e = lib.colour_errors(gt / 2.5, gt, "scalar")
        self.assertAlmostEqual(e["mean_rel"], 0, places=9)
        self.assertAlmostEqual(e["mean_de2000"], 0, places=6)
        cast = np.array([[1.01, 0.1, 0.03], [0.07, 0.88, 0.05], [0.04, 0.12, 0.68]])
        est = gt @ cast.T
        self.assertGreater(lib.colour_errors(est, gt, "scalar")["mean_de2000"], 1)
        self.assertAlmostEqual(lib.colour_errors(est, gt, "matrix")["mean_rel"], 0, places=9)
        self.assertEqual(lib.colour_errors(np.vstack([est, [[0, 0, 0]]]), np.vstack([gt, [[0, 0, 0]]]),
                                           "matrix")["dark_skipped"], 1)


class ScriptTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def test_sample_mlx_lists_every_parameter_with_meshlab_types(self):
        root = ET.parse(SAMPLE_MLX).getroot()
        self.assertEqual(root.tag, "FilterScript")
        params = {p.get("name"): p for p in root.find("filter").iter("Param")}
        self.assertEqual(root.find("filter").get("name"), "Vertex BRDF: fit per-vertex reflectance")
        types = {"lightFile": "RichString", "domeRadius": "RichFloat", "lightUnitScale": "RichFloat",
                 "outputPly": "RichString", "overwriteOutput": "RichBool", "specularThreshold": "RichFloat",
                 "diffuseThreshold": "RichFloat", "photoEncoding": "RichEnum", "saturationLevel": "RichFloat",
                 "visibilityBackend": "RichEnum", "depthTolerance": "RichFloat", "shadowMapSize": "RichInt",
                 "memoryBudgetMB": "RichInt", "fitReflectance": "RichBool", "fitBackend": "RichEnum",
                 "initialShininess": "RichFloat", "specularLobe": "RichEnum", "diffuseTerm": "RichEnum", "findMaterials": "RichBool", "sharpenAlbedoEdges": "RichBool", "refineRegistration": "RichBool", "refineNormals": "RichBool", "maxIterations": "RichInt", "minSpecularSamples": "RichInt", "fillUnseenRings": "RichInt",
                 "qualityOutput": "RichEnum", "colorCorrection": "RichEnum", "chartCorners": "RichString",
                 "exposureNormalisation": "RichEnum", "onlySelectedVertices": "RichBool"}
        self.assertEqual({n: p.get("type") for n, p in params.items()}, types)
        # Attributes MeshLab's reader needs, or it silently drops the parameter.
        for name in ("photoEncoding", "visibilityBackend", "colorCorrection", "exposureNormalisation"):
            self.assertEqual(params[name].get("enum_cardinality"), "3")

    def test_write_mlx_sets_values(self):
        out = os.path.join(self.tmp.name, "s.mlx")
        lib.write_mlx(SAMPLE_MLX, out, {"outputPly": "/x/y.ply", "visibilityBackend": 2})
        text = lib.read_text(out)
        self.assertTrue(text.startswith("<!DOCTYPE FilterScript>"))
        params = {p.get("name"): p.get("value") for p in ET.parse(out).getroot().iter("Param")}
        self.assertEqual(params["outputPly"], "/x/y.ply")
        self.assertEqual(params["visibilityBackend"], "2")
        self.assertEqual(params["specularThreshold"], "0.9")
        with self.assertRaises(KeyError):
            lib.write_mlx(SAMPLE_MLX, out, {"outputPLY": "typo"})

    def test_rewrite_mlp_makes_paths_absolute(self):
        src_dir = os.path.join(self.tmp.name, "p")
        os.makedirs(src_dir)
        src = os.path.join(src_dir, "project.mlp")
        with open(src, "w") as f:
            f.write('<!DOCTYPE MeshLabDocument>\n<MeshLabProject><MeshGroup><MLMesh label="m" filename="mesh.ply"/>'
                    '</MeshGroup><RasterGroup><MLRaster label="a"><VCGCamera/><Plane semantic="1" '
                    'fileName="images/a.png"/></MLRaster></RasterGroup></MeshLabProject>\n')
        dst = os.path.join(self.tmp.name, "copy.mlp")
        lib.rewrite_mlp(src, dst, photo_dir="/photos/linear")
        root = ET.parse(dst).getroot()
        self.assertEqual(root.find(".//MLMesh").get("filename"), os.path.join(src_dir, "mesh.ply"))
        self.assertEqual(root.find(".//Plane").get("fileName"), "/photos/linear/a.png")


class CheckOutputTest(unittest.TestCase):
    """check_output.check on a hand-made output: passes when right, names what is wrong."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        d = self.tmp.name
        n = 6
        self.faces = np.array([[0, 1, 2], [3, 4, 5]])
        mesh = mesh_vertex(n)
        self.mesh, self.gt, self.out = (os.path.join(d, f) for f in ("mesh.ply", "gt.ply", "out.ply"))
        lib.write_ply(self.mesh, mesh, self.faces)
        gt = mesh_vertex(n, extra=("albedo_r", "albedo_g", "albedo_b"))
        albedo = np.linspace(0.1, 0.9, 3 * n).reshape(n, 3)
        for i, c in enumerate(("albedo_r", "albedo_g", "albedo_b")):
            gt[c] = albedo[:, i]
        lib.write_ply(self.gt, gt, self.faces)
        out = mesh_vertex(n, colour=True, extra=check_output.REQUIRED[10:])
        for c in ("x", "y", "z"):
            out[c] = mesh[c]
        est = albedo * 0.5
        seen = np.array([1, 1, 1, 1, 0, 0], bool)
        for i, c in enumerate(("diffuse_r", "diffuse_g", "diffuse_b")):
            out[c] = np.where(seen, est[:, i], 0)
        rgb = np.round(255 * lib.linear_to_srgb(est)).astype(np.uint8)
        for i, c in enumerate(("red", "green", "blue")):
            out[c] = np.where(seen, rgb[:, i], 255)
        out["alpha"] = 255
        out["n_visible"] = np.where(seen, 3, 0)
        out["n_diffuse"] = np.where(seen, 2, 0)
        out["coloured"] = seen
        self.out_vertex = out

    def tearDown(self):
        self.tmp.cleanup()

    def run_check(self, vertex, faces=None):
        lib.write_ply(self.out, vertex, self.faces if faces is None else faces)
        return check_output.check(self.out, self.mesh, self.gt, "scalar", max_rel=0.01, max_de=0.5)

    def test_correct_output_passes(self):
        r = self.run_check(self.out_vertex)
        self.assertEqual(r["failures"], [])
        self.assertEqual(r["coloured"], 4)
        self.assertAlmostEqual(r["scalar"]["mean_rel"], 0, places=5)

    def test_lost_input_colour_is_reported(self):
        v = self.out_vertex.copy()
        v["red"][5] = 0
        self.assertTrue(any("lost their input colour" in f for f in self.run_check(v)["failures"]))

    def test_non_finite_and_missing_properties_are_reported(self):
        v = self.out_vertex.copy()
        v["diffuse_g"][4] = np.nan
        self.assertTrue(any("non-finite" in f for f in self.run_check(v)["failures"]))
        names = [n for n in self.out_vertex.dtype.names if n != "n_specular"]
        r = self.run_check(self.out_vertex[names])
        self.assertTrue(any("n_specular" in f for f in r["failures"]))

    def test_seen_vertex_without_model_and_inconsistent_reflectance_are_reported(self):
        names = list(self.out_vertex.dtype.names) + ["kd", "color_r", "color_g", "color_b", "fit_status"]
        v = np.zeros(len(self.out_vertex), dtype=[(n, self.out_vertex.dtype[n] if n in self.out_vertex.dtype.names
                                                    else np.float32) for n in names])
        for n in self.out_vertex.dtype.names:
            v[n] = self.out_vertex[n]
        rho = np.stack([v["diffuse_r"], v["diffuse_g"], v["diffuse_b"]], 1)
        v["kd"] = rho.max(axis=1)
        for i, c in enumerate(("color_r", "color_g", "color_b")):
            v[c] = np.where(v["kd"] > 0, rho[:, i] / np.maximum(v["kd"], 1e-30), 0)
        v["fit_status"] = np.where(v["n_visible"] > 0, 1, 0)
        self.assertEqual(self.run_check(v)["failures"], [])
        w = v.copy()
        w["fit_status"][1] = 0
        self.assertTrue(any("have no model" in f for f in self.run_check(w)["failures"]))
        w = v.copy()
        w["kd"][2] *= 1.1
        self.assertTrue(any("different from k_d * color" in f for f in self.run_check(w)["failures"]))

    def test_changed_geometry_and_bad_colour_are_reported(self):
        v = self.out_vertex.copy()
        v["x"][0] += 0.5
        self.assertTrue(any("positions differ" in f for f in self.run_check(v)["failures"]))
        r = self.run_check(self.out_vertex, faces=np.array([[0, 2, 1], [3, 4, 5]]))
        self.assertTrue(any("faces differ" in f for f in r["failures"]))
        v = self.out_vertex.copy()
        v["diffuse_b"][0] *= 3
        failures = self.run_check(v)["failures"]
        self.assertTrue(any("sRGB encoding" in f for f in failures))
        self.assertTrue(any("mean relative error" in f for f in failures))


if __name__ == "__main__":
    unittest.main()
