"""mmrtm-render as a user runs it: good input renders, bad input gets a
message naming the problem, a non-zero exit code and no output file.

Run by ctest with MMRTM_RENDER (the binary) and MMRTM_SHARED_DATA_DIR set.
"""
import json
import os
import struct
import subprocess
import tempfile
import unittest

RENDER = os.environ["MMRTM_RENDER"]
DATA = os.environ["MMRTM_SHARED_DATA_DIR"]
HEADSQ = os.path.join(DATA, "ct_head_headsq.nrrd")  # 64 x 64 x 93, small and fast


def read_pfm_pixels(data):
    """The floats of a colour PFM's bytes (little-endian, as mmrtm-render writes)."""
    header_end = 0
    for _ in range(3):
        header_end = data.index(b"\n", header_end) + 1
    width, height = (int(v) for v in data.split(b"\n")[1].split())
    return struct.unpack("<%df" % (width * height * 3), data[header_end:])


class RenderCli(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.png = os.path.join(self.dir, "out.png")

    def tearDown(self):
        self.tmp.cleanup()

    def run_render(self, *args):
        return subprocess.run([RENDER, *args, "--output", self.png, "--quiet"], capture_output=True, text=True,
                              timeout=300)

    def write(self, name, content, mode="w"):
        path = os.path.join(self.dir, name)
        with open(path, mode) as f:
            f.write(content)
        return path

    def expect_failure(self, result, *fragments, code=1):
        self.assertEqual(result.returncode, code, result.stderr)
        for fragment in fragments:
            self.assertIn(fragment, result.stderr)
        self.assertFalse(os.path.exists(self.png), "a failed run must not leave an image")
        self.assertEqual([f for f in os.listdir(self.dir) if f.startswith("out.")], [])

    def test_renders_and_reports(self):
        stats = os.path.join(self.dir, "stats.json")
        pfm = os.path.join(self.dir, "out.pfm")
        r = self.run_render(HEADSQ, "--width", "40", "--height", "30", "--spp", "4", "--seed", "3",
                            "--stats-json", stats, "--output-linear", pfm)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        with open(stats) as f:
            s = json.load(f)
        self.assertEqual((s["width"], s["height"], s["spp"], s["seed"]), (40, 30, 4, 3))
        self.assertEqual(s["paths"], 40 * 30 * 4)
        self.assertGreater(s["density_lookups"], 0)
        self.assertGreater(s["real_collisions"], 0)
        self.assertEqual(s["majorant_violations"], 0)
        self.assertGreater(s["noise"]["relative"], 0)
        self.assertGreater(s["samples_per_second"], 0)
        with open(pfm, "rb") as f:
            header = f.readline() + f.readline() + f.readline()
            self.assertEqual(header.split()[:3], [b"PF", b"40", b"30"])
            pixels = struct.unpack("<%df" % (40 * 30 * 3), f.read())
        self.assertGreater(max(pixels), 0.0)

    def test_every_preset_renders(self):
        cases = {
            "ct-bone": [HEADSQ],
            "ct-soft-tissue": [HEADSQ],
            "ct-angio-labels": [os.path.join(DATA, "cta_chest_aorta.nii.gz"), "--labels",
                                os.path.join(DATA, "cta_chest_aorta_labels.nii.gz")],
            "mri": [os.path.join(DATA, "mr_head.nii.gz")],
            "ct-organs": [os.path.join(DATA, "ct_abdomen.nii.gz"), "--labels",
                          os.path.join(DATA, "ct_abdomen_labels.nii.gz"), "--label-table",
                          os.path.join(DATA, "ct_abdomen_labels.txt")],
        }
        presets = sorted(f[:-5] for f in os.listdir(os.path.join(os.path.dirname(__file__), "..", "..", "Data",
                                                                 "presets")) if f.endswith(".json"))
        self.assertEqual(presets, sorted(cases))
        for preset, args in cases.items():
            stats = os.path.join(self.dir, preset + ".json")
            r = self.run_render(*args, "--preset", preset, "--width", "24", "--height", "24", "--spp", "2",
                                "--stats-json", stats)
            self.assertEqual(r.returncode, 0, preset + ": " + r.stderr)
            with open(stats) as f:
                self.assertGreater(json.load(f)["real_collisions"], 0, preset + " shows nothing")

    def test_label_preset_without_labels(self):
        self.expect_failure(self.run_render(HEADSQ, "--preset", "ct-angio-labels"), "no proxy volume named 'labels'")

    def test_accelerators_cut_density_lookups(self):
        lookups = {}
        for accelerator in ["none", "macrocell", "octree", "octree-voxelmax"]:
            stats = os.path.join(self.dir, accelerator + ".json")
            r = self.run_render(HEADSQ, "--accelerator", accelerator, "--width", "32", "--height", "32",
                                "--spp", "4", "--stats-json", stats)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(stats) as f:
                s = json.load(f)
            self.assertGreater(s["real_collisions"], 0)
            lookups[accelerator] = s["density_lookups_per_real_collision"]
        self.assertLess(lookups["octree"], lookups["none"] / 2, lookups)
        self.assertLess(lookups["macrocell"], lookups["none"] / 2, lookups)

    def test_dicom_folder_and_series(self):
        chest = os.path.join(DATA, "ct_chest_dicom")
        r = subprocess.run([RENDER, chest, "--list-series"], capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        uid = r.stdout.split("\t")[0]
        self.assertIn("92 slices", r.stdout)
        r = self.run_render(chest, "--series", uid, "--width", "24", "--height", "24", "--spp", "1")
        self.assertEqual(r.returncode, 0, r.stderr)
        os.remove(self.png)
        self.expect_failure(self.run_render(chest, "--series", "1.2.3"), "ct_chest_dicom",
                            "no series with the UID or description \"1.2.3\"", uid)

    def test_label_table_errors(self):
        ct = os.path.join(DATA, "ct_abdomen.nii.gz")
        labels = os.path.join(DATA, "ct_abdomen_labels.nii.gz")
        self.expect_failure(self.run_render(ct, "--labels", labels, "--preset", "ct-organs", "--label-table",
                                            os.path.join(self.dir, "none.txt")), "none.txt")
        table = self.write("bad.txt", "1 liver 255 0 0\n1 spleen\n")
        self.expect_failure(self.run_render(ct, "--labels", labels, "--preset", "ct-organs", "--label-table", table),
                            "bad.txt:2")
        self.expect_failure(self.run_render(ct, "--preset", "ct-organs"), "label_materials", "--labels")

    def test_labels_that_miss_the_volume(self):
        # The label map shifted 10 m away in its header: nothing to align.
        far = self.write("far.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                                     "space: left-posterior-superior\nspace origin: (10000,0,0)\n"
                                     "space directions: (1,0,0) (0,1,0) (0,0,1)\n\n")
        with open(far, "ab") as f:
            f.write(bytes([0, 1, 1, 1, 1, 1, 1, 1]))
        self.expect_failure(self.run_render(os.path.join(DATA, "cta_chest_aorta.nii.gz"), "--labels", far,
                                            "--preset", "ct-angio-labels"), "far.nrrd", "overlap")

    def test_backend_choice(self):
        # auto renders anywhere; cuda renders with a device and is a clear
        # error without one (CI has nvcc but no GPU).
        stats = os.path.join(self.dir, "auto.json")
        r = self.run_render(HEADSQ, "--width", "16", "--height", "16", "--spp", "1", "--stats-json", stats)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(stats) as f:
            auto = json.load(f)["backend"]
        os.remove(self.png)
        r = self.run_render(HEADSQ, "--backend", "cuda", "--width", "16", "--height", "16", "--spp", "1")
        if auto.startswith("cuda"):
            self.assertEqual(r.returncode, 0, r.stderr)
        else:
            self.assertTrue(auto.startswith("cpu"), auto)
            self.expect_failure(r, "--backend cuda: ")
        self.expect_failure(self.run_render(HEADSQ, "--backend", "gpu"), "--backend expects auto, cpu or cuda", code=2)

    def render_linear(self, name, *args):
        stats, pfm = os.path.join(self.dir, name + ".json"), os.path.join(self.dir, name + ".pfm")
        r = self.run_render(HEADSQ, "--width", "40", "--height", "30", "--seed", "5", "--stats-json", stats,
                            "--output-linear", pfm, *args)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(stats) as f, open(pfm, "rb") as g:
            return json.load(f), g.read()

    def test_noise_target(self):
        # A target it cannot reach: all --spp samples, in passes of 4, 8 and
        # 4 that continue one sample sequence: the same image, to the bit, as
        # one pass of 16.
        whole, whole_pixels = self.render_linear("whole", "--spp", "16")
        passes, pass_pixels = self.render_linear("passes", "--spp", "16", "--noise-target", "1e-6")
        self.assertEqual((passes["spp"], passes["stopped_on"], passes["noise_target"]), (16, "spp", 1e-6))
        self.assertEqual((whole["stopped_on"], whole["noise_target"]), ("spp", None))
        self.assertEqual(pass_pixels, whole_pixels)
        # A reachable one: it stops early, on a noise at most the target,
        # after more samples than a pass of 4 (which is noisier than 0.1 here).
        stopped, _ = self.render_linear("stopped", "--spp", "4096", "--noise-target", "0.1")
        self.assertEqual(stopped["stopped_on"], "noise_target")
        self.assertLessEqual(stopped["noise"]["relative"], 0.1)
        self.assertGreater(stopped["spp"], 4)
        self.assertLess(stopped["spp"], 4096)
        os.remove(self.png)
        self.expect_failure(self.run_render(HEADSQ, "--noise-target", "0"), "--noise-target", code=2)
        self.expect_failure(self.run_render(HEADSQ, "--noise-target", "two"), "--noise-target", code=2)

    def test_adaptive_sampling(self):
        # A mean of 16 spp split by the pilot's noise: the counts differ from
        # pixel to pixel, never below the pilot's (16 / 8 = 2), and the mean
        # is what was asked for.
        adaptive, pixels = self.render_linear("adaptive", "--spp", "16", "--sampling", "adaptive")
        self.assertEqual(adaptive["sampling"], "adaptive")
        self.assertAlmostEqual(adaptive["spp"], 16, delta=0.2)
        self.assertEqual(adaptive["spp_min"], 2)
        self.assertGreater(adaptive["spp_max"], 32)
        self.assertAlmostEqual(adaptive["paths"], 40 * 30 * adaptive["spp"], delta=1)
        again, same = self.render_linear("again", "--spp", "16", "--sampling", "adaptive", "--threads", "1")
        self.assertEqual(same, pixels, "the same image at any thread count")
        uniform, _ = self.render_linear("uniform", "--spp", "16", "--sampling", "uniform")
        self.assertEqual((uniform["sampling"], uniform["spp"], uniform["spp_min"], uniform["spp_max"]),
                         ("uniform", 16, 16, 16))
        # With a target: passes of the pilot's split until the noise is met.
        stopped, _ = self.render_linear("stopped", "--spp", "4096", "--noise-target", "0.1", "--sampling", "adaptive")
        self.assertEqual(stopped["stopped_on"], "noise_target")
        self.assertLessEqual(stopped["noise"]["relative"], 0.1)
        os.remove(self.png)
        self.expect_failure(self.run_render(HEADSQ, "--sampling", "smart"), "--sampling", code=2)

    def test_light_sampling(self):
        stats = {}
        for mode in ("one", "all", "resampled"):
            stats[mode], _ = self.render_linear(mode, "--spp", "8", "--light-sampling", mode)
        # The preset has a sky and a sun: every event sends one shadow ray at
        # most, except with all, which sends one to each.
        self.assertGreater(stats["all"]["shadow_rays"], 1.5 * stats["one"]["shadow_rays"])
        self.assertLessEqual(stats["resampled"]["shadow_rays"], stats["resampled"]["real_collisions"])
        os.remove(self.png)
        self.expect_failure(self.run_render(HEADSQ, "--light-sampling", "some"), "--light-sampling", code=2)
        scene = self.write("scene.json", json.dumps({"render": {"light_sampling": "every"}}))
        self.expect_failure(self.run_render(HEADSQ, "--preset", "ct-bone", "--scene", scene), "render.light_sampling", "every")

    def test_pixel_sampler(self):
        # Sobol' pairs by default, reported; other numbers than independent
        # ones; the same image at any thread count.
        sobol, sobol_pixels = self.render_linear("sobol", "--spp", "8")
        self.assertEqual(sobol["sampler"], "sobol")
        _, again = self.render_linear("again", "--spp", "8", "--threads", "1", "--sampler", "sobol")
        self.assertEqual(again, sobol_pixels, "the same image at any thread count")
        independent, independent_pixels = self.render_linear("independent", "--spp", "8", "--sampler", "independent")
        self.assertEqual(independent["sampler"], "independent")
        self.assertNotEqual(independent_pixels, sobol_pixels)
        os.remove(self.png)
        self.expect_failure(self.run_render(HEADSQ, "--sampler", "halton"), "--sampler", code=2)
        scene = self.write("scene.json", json.dumps({"render": {"sampler": "halton"}}))
        self.expect_failure(self.run_render(HEADSQ, "--preset", "ct-bone", "--scene", scene), "render.sampler", "halton")

    def test_denoise(self):
        # No library: an error before rendering that names what was tried; no output.
        png = os.path.join(self.dir, "preview.png")
        for flags in (["--denoised-preview", png], ["--denoise", "auto"]):
            r = subprocess.run([RENDER, HEADSQ, "--spp", "1", *flags, "--output", self.png, "--quiet"],
                               capture_output=True, text=True, timeout=300,
                               env=dict(os.environ, MMRTM_OIDN_LIBRARY=os.path.join(self.dir, "libnone.so")))
            self.expect_failure(r, "Open Image Denoise not found", "libnone.so")
            self.assertFalse(os.path.exists(png))
            self.assertFalse(os.path.exists(self.png))
        self.expect_failure(self.run_render(HEADSQ, "--denoise", "sometimes"), "--denoise expects off, auto or always",
                            code=2)
        self.expect_failure(self.run_render(HEADSQ, "--denoised-preview", os.path.join(self.dir, "p.exr")),
                            "--denoised-preview expects a .png or .pfm", code=2)
        self.expect_failure(self.run_render(HEADSQ, "--spp", "1", "--output-denoiser-inputs",
                                            os.path.join(self.dir, "inputs")), "needs 2 or more samples")
        if os.environ.get("MMRTM_SANITIZED"):
            self.skipTest("Open Image Denoise under sanitizers: its TBB dlopens with RTLD_DEEPBIND, which the "
                          "sanitizer runtime refuses (the Release build runs this test)")
        r = self.run_render(HEADSQ, "--width", "8", "--height", "8", "--spp", "1", "--denoised-preview", png)
        if r.returncode != 0 and "Open Image Denoise not found" in r.stderr:
            self.skipTest("no Open Image Denoise library (scripts/install-dependencies.sh installs the pyoidn "
                          "wheel): " + r.stderr.strip().splitlines()[-1])
        self.assertEqual(r.returncode, 0, r.stderr)
        # The unbiased outputs are the same bits whatever is denoised or
        # shown (Documentation/denoising.md).
        preview = os.path.join(self.dir, "preview.pfm")
        plain, plain_pixels = self.render_linear("plain", "--spp", "4")
        self.assertIsNone(plain["denoising"])
        for mode in ("off", "auto", "always"):
            stats, pixels = self.render_linear(mode, "--spp", "4", "--denoise", mode, "--denoised-preview", preview)
            self.assertEqual(pixels, plain_pixels, mode)
            d = stats["denoising"]
            self.assertIn("Open Image Denoise 2.", d["denoiser"])
            self.assertEqual(d["mode"], mode)
            self.assertEqual(d["shown"], mode != "off")  # 4 spp: auto finds the denoised image closer
            self.assertEqual(d["biased"], d["shown"])
            self.assertEqual(d["guides"], "first-hit albedo and normal, denoised")
            if mode == "auto":
                e = d["estimate"]
                self.assertLess(e["denoised_relative_error"], e["film_relative_error"])
            else:
                self.assertIsNone(d["estimate"])
        # A 1-spp denoised image is nearer a 256-spp render (another seed)
        # than the 1-spp image is (0.27-0.28 of its RMSE over four seeds;
        # held to 0.4), and as bright (measured within 0.3 %; held to 3 %):
        # not a black or blurred-away image.
        size = ("--width", "80", "--height", "60")
        _, raw = self.render_linear("raw", *size, "--spp", "1", "--denoised-preview", preview)
        _, reference = self.render_linear("reference", *size, "--spp", "256", "--seed", "9")
        ref, raw = read_pfm_pixels(reference), read_pfm_pixels(raw)
        with open(preview, "rb") as f:
            denoised = read_pfm_pixels(f.read())
        rmse = lambda a: (sum((x - y) ** 2 for x, y in zip(a, ref)) / len(ref)) ** 0.5  # noqa: E731
        self.assertLess(rmse(denoised), 0.4 * rmse(raw), (rmse(denoised), rmse(raw)))
        self.assertAlmostEqual(sum(denoised) / sum(ref), 1.0, delta=0.03)
        # The denoiser's inputs: the even and the odd half average to the
        # film; the guides are written beside them.
        prefix = os.path.join(self.dir, "inputs")
        _, film = self.render_linear("inputs", "--spp", "4", "--output-denoiser-inputs", prefix)
        halves = []
        for name in ("color_even", "color_odd"):
            with open("%s_%s.pfm" % (prefix, name), "rb") as f:
                halves.append(read_pfm_pixels(f.read()))
        film = read_pfm_pixels(film)
        self.assertEqual(len(halves[0]), len(film))
        self.assertLess(max(abs((a + b) / 2 - c) for a, b, c in zip(*halves, film)), 1e-4)
        self.assertNotEqual(halves[0], halves[1])
        for name in ("albedo", "normal", "albedo_even", "albedo_odd", "normal_even", "normal_odd"):
            self.assertTrue(os.path.exists("%s_%s.pfm" % (prefix, name)), name)
        # --denoise always writes the denoised image as --output.
        shown = os.path.join(self.dir, "shown.png")
        r = subprocess.run([RENDER, HEADSQ, *size, "--spp", "2", "--denoise", "always", "--denoised-preview", png,
                            "--output", shown, "--quiet"], capture_output=True, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(shown, "rb") as a, open(png, "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_degenerate_volumes(self):
        # One voxel, a 1 x 1 x 1000 line, a single slice: nothing to render,
        # said clearly instead of an empty image (or a camera error).
        header = "NRRD0004\ntype: float\ndimension: 3\nsizes: %d %d %d\nencoding: raw\nendian: little\n\n"
        for name, sizes in [("one.nrrd", (1, 1, 1)), ("line.nrrd", (1, 1, 1000)), ("slice.nrrd", (50, 50, 1))]:
            count = sizes[0] * sizes[1] * sizes[2]
            path = self.write(name, header.encode() % sizes + struct.pack("<%df" % count, *([1000.0] * count)), "wb")
            self.expect_failure(self.run_render(path), name, "at least 2 voxels along every axis")

    def test_missing_input(self):
        self.expect_failure(self.run_render(os.path.join(self.dir, "nope.nrrd")), "nope.nrrd")

    def test_unsupported_file_type(self):
        path = self.write("volume.xyz", "not a volume")
        self.expect_failure(self.run_render(path), "volume.xyz")

    def test_non_finite_volume(self):
        # NaN voxels render (as the least value) with one warning naming the
        # file; an infinite voxel is still an error naming it.
        header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nendian: little\n\n"
        values = struct.pack("<8f", 0, 1, 2, float("nan"), 4, 5, 6, 7)
        path = self.write("nan.nrrd", header.encode() + values, "wb")
        result = self.run_render(path, "--spp", "1", "--width", "16", "--height", "16")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stderr.count("warning: "), 1, result.stderr)
        self.assertIn("nan.nrrd: 1 NaN voxel", result.stderr)
        self.assertTrue(os.path.exists(self.png))
        os.remove(self.png)
        values = struct.pack("<8f", 0, 1, 2, float("inf"), 4, 5, 6, 7)
        path = self.write("inf.nrrd", header.encode() + values, "wb")
        self.expect_failure(self.run_render(path), "inf.nrrd", "non-finite")

    def peak_resident_bytes_of_render(self, volume):
        """Renders `volume` (64 x 64, 1 spp) in a child process of its own
        and returns that child's peak resident bytes (wait4's rusage)."""
        with open(os.path.join(self.dir, "stderr.txt"), "w") as err:
            child = subprocess.Popen([RENDER, volume, "--width", "64", "--height", "64", "--spp", "1", "--quiet",
                                      "--output", self.png], stderr=err)
            _, status, usage = os.wait4(child.pid, 0)
            child.returncode = os.waitstatus_to_exitcode(status)
        with open(os.path.join(self.dir, "stderr.txt")) as err:
            self.assertEqual(child.returncode, 0, err.read())
        return usage.ru_maxrss * 1024

    def test_a_large_volume_is_held_once(self):
        """A 256 MiB raw int16 NRRD (512^3, made here) raises mmrtm-render's
        peak resident memory by at most 1.15 x its voxel bytes over the run
        of a 0.7 MiB volume (the program's fixed cost): the voxels, the grid
        (0.1 x for int16) and the summaries. Catches a second copy of the
        voxels on the way in (a reader's array copied out: +1 x) or a float
        volume between file and tracer (+2 x)."""
        if os.environ.get("MMRTM_SANITIZED"):
            self.skipTest("peak memory under sanitizers counts their shadow memory and quarantine, not the "
                          "program's (the Release build runs this test)")
        n = 512
        path = os.path.join(self.dir, "large.nrrd")
        with open(path, "wb") as f:
            f.write(("NRRD0004\ntype: short\ndimension: 3\nsizes: %d %d %d\nspacings: 1 1 1\n"
                     "endian: little\nencoding: raw\n\n" % (n, n, n)).encode())
            # A bright ball in air, so that the grid has work to summarise.
            for z in range(n):
                row = []
                for y in range(n):
                    r2 = (z - n / 2) ** 2 + (y - n / 2) ** 2
                    half = int(max(0.0, (n * n / 9 - r2)) ** 0.5)
                    row.append(struct.pack("<%dh" % n, *([0] * (n // 2 - half) + [1500] * (2 * half)
                                                         + [0] * (n - n // 2 - half))))
                f.write(b"".join(row))
        voxel_bytes = 2 * n ** 3
        fixed = self.peak_resident_bytes_of_render(HEADSQ)
        large = self.peak_resident_bytes_of_render(path)
        self.assertLessEqual(large - fixed, 1.15 * voxel_bytes,
                             "peak %d MiB, %d MiB for a 0.7 MiB volume: %.2f x the %d MiB of voxels"
                             % (large >> 20, fixed >> 20, (large - fixed) / voxel_bytes, voxel_bytes >> 20))
        self.assertGreaterEqual(large - fixed, 0.8 * voxel_bytes, "the voxels are resident: the measure works")

    def test_truncated_volume(self):
        with open(HEADSQ, "rb") as f:
            data = f.read()
        path = self.write("cut.nrrd", data[: len(data) // 2], "wb")
        self.expect_failure(self.run_render(path), "cut.nrrd")

    def test_scene_naming_a_missing_proxy(self):
        scene = self.write("scene.json", json.dumps({
            "materials": {"m": {"tfs": {"density": [{"type": "cctf", "proxy": "labels", "points": [[0, 1]]}]}}}}))
        self.expect_failure(self.run_render(HEADSQ, "--scene", scene), "no proxy volume named 'labels'")

    def test_transfer_function_without_points(self):
        scene = self.write("scene.json", json.dumps({
            "materials": {"m": {"tfs": {"density": [{"type": "cctf", "points": []}]}}}}))
        self.expect_failure(self.run_render(HEADSQ, "--scene", scene), "materials.m.tfs.density[0]",
                            "at least one point")

    def test_unknown_scene_key(self):
        scene = self.write("scene.json", json.dumps({"materials": {"m": {"albdeo": [1, 1, 1]}}}))
        self.expect_failure(self.run_render(HEADSQ, "--scene", scene), "unknown key 'albdeo'")

    def test_invalid_json(self):
        scene = self.write("scene.json", "{\"materials\": ")
        self.expect_failure(self.run_render(HEADSQ, "--scene", scene), "scene.json", "not valid JSON")

    def test_deeply_nested_json(self):
        # 2 million levels (4 MB) overflowed the stack when the document
        # was copied; 101 levels are already refused, with brackets in
        # strings and comments not counted.
        for depth in (101, 2000000):
            scene = self.write("scene.json", '{"camera": ' + "[" * depth + "]" * depth + "}")
            self.expect_failure(self.run_render(HEADSQ, "--scene", scene), "scene.json",
                                "nested %d levels deep" % (depth + 1))
        scene = self.write("scene.json", '// [[[[ {{{{\n{"materials": {"m": {"albdeo": "[[[[ {{{{ /*"}}} /* ]]]] */')
        self.expect_failure(self.run_render(HEADSQ, "--scene", scene), "unknown key 'albdeo'")

    def test_unknown_preset(self):
        self.expect_failure(self.run_render(HEADSQ, "--preset", "nope"), "no preset named 'nope'", "ct-bone")

    def test_bad_option_value(self):
        self.expect_failure(self.run_render(HEADSQ, "--spp", "many"), "--spp", code=2)
        self.expect_failure(self.run_render(HEADSQ, "--frobnicate"), "unknown option", code=2)
        self.expect_failure(self.run_render(HEADSQ, "--accelerator", "kd-tree"), "--accelerator", code=2)

    def test_output_folder_missing(self):
        r = subprocess.run([RENDER, HEADSQ, "--output", os.path.join(self.dir, "no", "out.png"), "--quiet"],
                           capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 1)
        self.assertIn("does not exist", r.stderr)

    def test_help_lists_every_option(self):
        r = subprocess.run([RENDER, "--help"], capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0)
        for option in ["--scene", "--preset", "--labels", "--label-table", "--series", "--list-series", "--backend", "--width", "--height", "--spp", "--seed", "--threads",
                       "--estimator", "--output", "--output-linear", "--stats-json", "--noise-target", "--sampling",
                       "--light-sampling", "--sampler", "--denoise", "--denoised-preview",
                       "--output-denoiser-inputs"]:
            self.assertIn(option, r.stdout)


if __name__ == "__main__":
    unittest.main()
