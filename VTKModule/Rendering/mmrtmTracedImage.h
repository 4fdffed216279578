// PRIVATE to MMRTM::Rendering: the mapper's input as the image the tracer
// samples, a vtkImageData with point scalars at least 2 points along every
// axis. VTK's volume mappers take more than that; each other input is
// converted here, so that the rest of the mapper sees one kind:
//
// - cell scalars (ScalarMode picks cell data): an image whose points are the
//   cell centres (one point fewer along every axis with more than one), the
//   cell values at them, interpolated between centres as point scalars are
//   (VTK's GPU mapper does the same with its cell texture; the outer half
//   cell, outside the centres, is not rendered);
// - a vtkRectilinearGrid (point scalars): resampled, trilinearly, onto a
//   uniform grid whose spacing along each axis is the smallest gap between
//   its coordinates (at most kMaxRefinement times the axis's points), in
//   the scalars' own type (integers rounded); axes already uniform are
//   copied as they are;
// - a single slice (one point along an axis, after the above): two copies
//   of it half a spacing either side (spacing 1 where it is 0), a slab one
//   voxel thick, as a slice of voxels is.
#pragma once

#include <string>

#include <vtkSmartPointer.h>

class vtkDataArray;
class vtkDataSet;
class vtkImageData;

namespace mmrtm
{

// A rectilinear axis is refined at most this many times (its uniform
// spacing is at least the axis's length / (this x its gaps)): a grid with
// one tiny gap would otherwise become a huge volume.
constexpr int kMaxRefinement = 4;

struct TracedImage
{
  vtkSmartPointer<vtkImageData> Image; // null: the input itself is such an image
  vtkDataArray* Scalars = nullptr;     // Image's point scalars (null with Image)
  std::string Conversion;              // what was done, for a message ("" when nothing)
};

// `scalars` is the array the mapper's ScalarMode picked from `input` and
// `cellScalars` whether it is cell data. Throws InputError naming the problem
// for inputs it cannot convert (another dataset type, cell scalars on a
// rectilinear grid, coordinates that are not ascending).
TracedImage ImageForTracing(vtkDataSet* input, vtkDataArray* scalars, bool cellScalars);

} // namespace mmrtm
