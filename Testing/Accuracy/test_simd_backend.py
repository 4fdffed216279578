"""The five reference scenes at a small size: the CPU's SIMD backend
(--simd on) and the scalar one (--simd off) give the same image.

Two checks a scene:
  - the same seed gives the same image to the last bit (the SIMD backend is
    built to round as the scalar code does: Documentation/decisions.md);
  - independent renders of the two (other seeds) agree within noise, by the
    block z-test of the accuracy checks (mmrtm_accuracy.block_agreement;
    two unbiased estimates fail with probability below 1e-4), with its
    power (the smallest change of one channel's mean over the covered
    pixels that fails with probability 1 - 1e-4) asserted below MAX_POWER.
    This is the check that stays when a later SIMD stage may round
    differently; its power is shown on the data: the SIMD image with a bias
    of that size planted in one channel must fail.
Variances are each image's error: REPLICATES independently scrambled Sobol'
renders a side (their spread; a Sobol' render's own spread overstates its
error about threefold).
Run by CTest (accuracy-simd-backend) with MMRTM_BUILD_DIR set.
"""

import unittest

import numpy as np

import mmrtm_accuracy as acc

SIZE = 48
SPP = 64
REPLICATES = 4
BLOCK = 8  # as test_estimators_agree: 64 pixels a block average the heavy tails out
MAX_POWER = 0.025
UNBIASED = ["--shadow-scale", "1", "--backend", "cpu"]


class SimdBackend(unittest.TestCase):
    def check(self, name):
        args = acc.SCENES[name]["args"]
        per = SPP // REPLICATES
        scalar = acc.render_replicates(args, SIZE, SIZE, per, [10 + r for r in range(REPLICATES)],
                                       [*UNBIASED, "--simd", "off"])
        simd = acc.render_replicates(args, SIZE, SIZE, per, [20 + r for r in range(REPLICATES)],
                                     [*UNBIASED, "--simd", "on"])
        self.assertIn("scalar", scalar.stats["backend"])
        self.assertIn("SIMD", simd.stats["backend"], f"{name}: the SIMD backend did not run")
        self.assertGreater(scalar.mean.mean(), 0.02, f"{name}: a black image proves nothing")

        same_seed = acc.render(args, SIZE, SIZE, per, seed=10, extra=[*UNBIASED, "--simd", "on"])
        self.assertTrue(np.array_equal(same_seed.mean, scalar.replicates[0]),
                        f"{name}: the SIMD backend's image is not the scalar one's for the same seed")

        def compare(simd_mean):
            return acc.block_agreement(scalar.mean, scalar.variance, simd_mean, simd.variance, block=BLOCK,
                                       df_a=REPLICATES - 1, df_b=REPLICATES - 1, replicates_a=scalar.replicates,
                                       replicates_b=simd.replicates)

        result = compare(simd.mean)
        print(f"{name}: scalar vs SIMD: {acc.describe(result)}")
        self.assertTrue(acc.agrees(result), f"{name}: scalar and SIMD disagree: {acc.describe(result)}")
        self.assertLessEqual(result["power"], MAX_POWER, f"{name}: {acc.describe(result)}")
        # The power, planted: one channel of the SIMD image off by that much
        # where it has noise (the covered pixels the power is stated over).
        biased = simd.mean.copy()
        covered = simd.variance[..., 0] > 0
        biased[..., 0][covered] *= 1 + result["power"]
        planted = compare(biased)
        print(f"{name}: red x(1 + {result['power']:.4f}) planted: {acc.describe(planted)}")
        self.assertFalse(acc.agrees(planted), f"{name}: a bias of the stated power passed: {acc.describe(planted)}")

    def test_head_ct_bone(self):
        self.check("head_ct_bone")

    def test_chest_ct(self):
        self.check("chest_ct")

    def test_cta_labels(self):
        self.check("cta_labels")

    def test_bonsai(self):
        self.check("bonsai")

    def test_mri_labels(self):
        self.check("mri_labels")


if __name__ == "__main__":
    unittest.main()
