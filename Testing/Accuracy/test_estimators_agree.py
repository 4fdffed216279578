"""The five reference scenes at a small size: the unbiased estimators agree.

Delta tracking with one global majorant (no accelerator), the macrocell grid
and the octree must give the same image within noise (different seeds, so
independent noise), on each real scene of the accuracy report; and the check
must be able to see a difference: the biased default shadow scale (0.8) and
coarse ray marching both fail it. Agreement: mmrtm_accuracy.block_agreement.

The accelerators are compared with independent samples (--sampler
independent), whose per-pixel variances are what the z-test assumes. The
default Sobol' sampler must agree with them too; its variances overstate
its error (its samples are stratified: two Sobol' renders of this size
compare at a mean z^2 of 0.3 to 0.6, two independent ones at about 1), so
its check is one-sided, and it is the sampler of the biased renders that
must fail.
Run by CTest (accuracy-estimators-agree) with MMRTM_BUILD_DIR set.
"""

import unittest

import mmrtm_accuracy as acc

SIZE = 48
SPP = 64
UNBIASED = ["--shadow-scale", "1"]
INDEPENDENT = ["--sampler", "independent"]


class EstimatorsAgree(unittest.TestCase):
    def check(self, name):
        args = acc.SCENES[name]["args"]
        none = acc.render(args, SIZE, SIZE, SPP, seed=1, extra=[*UNBIASED, *INDEPENDENT, "--accelerator", "none"])
        self.assertGreater(none.mean.mean(), 0.02, f"{name}: a black image proves nothing")
        for seed, accel, sampler in ((2, "macrocell", INDEPENDENT), (3, "octree", INDEPENDENT), (6, "octree", [])):
            other = acc.render(args, SIZE, SIZE, SPP, seed=seed, extra=[*UNBIASED, *sampler, "--accelerator", accel])
            label = f"{accel}, {other.stats['sampler']} sampler"
            result = acc.block_agreement(none.mean, none.variance, other.mean, other.variance, block=4)
            print(f"{name}: none vs {label}: mean z^2 {result['mean_z2']:.3f} (limit {result['limit']:.3f}, "
                  f"{result['terms']} terms)")
            self.assertTrue(acc.agrees(result), f"{name}: none and {label} disagree: {result}")
            self.assertEqual(other.stats["majorant_violations"], 0)
        return none

    def test_head_ct_bone(self):
        none = self.check("head_ct_bone")
        # The check sees biases: the default shadow scale brightens the image...
        biased = acc.render(acc.SCENES["head_ct_bone"]["args"], SIZE, SIZE, SPP, seed=4)
        result = acc.block_agreement(none.mean, none.variance, biased.mean, biased.variance, block=4)
        self.assertFalse(acc.agrees(result), f"shadow scale 0.8 passed as unbiased: {result}")
        # ...and so does coarse ray marching (its step misses thin bone).
        marched = acc.render(acc.SCENES["head_ct_bone"]["args"], SIZE, SIZE, SPP, seed=5,
                             extra=[*UNBIASED, "--estimator", "raymarch", "--ray-march-step", "4"])
        result = acc.block_agreement(none.mean, none.variance, marched.mean, marched.variance, block=4)
        self.assertFalse(acc.agrees(result), f"4 mm ray marching passed as unbiased: {result}")

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
