// Puts a label map on the voxel grid of the volume it labels. Label maps
// are read with nearest lookup; one that lies on its volume's grid keeps
// every label boundary where the segmentation put it, and costs no second
// set of grid geometry. Host-only set-up code.
#pragma once

#include "host_volume.h"

namespace mmrtm {

// Returns `labels` unchanged if it already lies on `reference`'s grid (same
// dims, and every reference voxel centre within 1e-3 voxel of the label
// voxel with the same index). Otherwise resamples it, nearest neighbour,
// onto reference's voxel centres and sets *resampled = true: a centre takes
// the label voxel whose centre is closest (the continuous label index
// rounded half up, as VolumeView's nearest lookup does); centres outside
// the label map's domain ([-0.5, n-0.5) on each index axis) get 0,
// background. The result keeps the labels' voxel type, name and source and
// takes reference's dims and indexToWorld.
// Throws InputError naming both sources if the label map's world box does
// not overlap the reference's, or if no non-zero label survives.
HostVolume AlignLabelsToVolume(HostVolume labels, const HostVolume& reference, bool* resampled = nullptr);

}  // namespace mmrtm
