"""The same scene, seed and sample count rendered by the mapper built
against Debian's VTK 9.1 and by the one in the Python wheel for the PyPI VTK
9.6 gives the same film, to the last bit.

Both builds compile the same tracer with the same compiler and flags; the
old libstdc++ ABI of the wheel changes how std::string and std::list are laid
out, not floating-point code. What VTK hands the mapper (the sampled
transfer functions, the camera matrices) could still differ between
versions; then some pixels' paths would diverge and this test reports how
many, and by how much, instead of hiding it under a tolerance.

Run by ctest under Testing/headless.sh (its own Xvfb). Environment: MMRTM_VTK91_PYTHON and
MMRTM_VTK91_PYTHONPATH (Debian's interpreter and the build tree's package),
MMRTM_VTK96_PYTHON (the venv's interpreter, with the wheel installed).
"""
import array
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))


def render(python, pythonpath, scene, out):
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    r = subprocess.run([python, os.path.join(HERE, "render_film.py"), scene, out], env=env,
                       capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        raise AssertionError("%s render_film.py failed:\n%s" % (python, r.stderr[-4000:]))
    print(r.stdout.strip())
    with open(out, "rb") as f:
        header = f.readline().split()
        values = array.array("f")
        values.frombytes(f.read())
    return tuple(int(v) for v in header), values


class FlavoursAgree(unittest.TestCase):
    def compare(self, scene):
        with tempfile.TemporaryDirectory() as tmp:
            shape91, film91 = render(os.environ["MMRTM_VTK91_PYTHON"], os.environ.get("MMRTM_VTK91_PYTHONPATH"),
                                     scene, os.path.join(tmp, "vtk91.film"))
            shape96, film96 = render(os.environ["MMRTM_VTK96_PYTHON"], None, scene, os.path.join(tmp, "vtk96.film"))
        self.assertEqual(shape91, shape96, "width, height and samples per pixel")
        width, height, _ = shape91
        self.assertEqual(len(film91), width * height * 4)
        covered = sum(1 for i in range(3, len(film91), 4) if film91[i] > 0.01)
        self.assertGreater(covered, 0.05 * width * height, "the film shows the volume (not an empty render)")
        differing = [i for i in range(len(film91)) if film91[i] != film96[i]]
        largest = max((abs(film91[i] - film96[i]) for i in differing), default=0.0)
        print("%s: covered pixels %d of %d; differing values %d of %d (largest difference %g)" % (
            scene, covered, width * height, len(differing), len(film91), largest))
        self.assertEqual(differing, [], "the films differ in %d values, by up to %g" % (len(differing), largest))

    def test_ct(self):
        self.compare("ct")

    def test_labels_gradient_opacity_and_mesh(self):
        self.compare("labels-mesh")


if __name__ == "__main__":
    unittest.main()
