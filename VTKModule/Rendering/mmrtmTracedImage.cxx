#include "mmrtmTracedImage.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkPointData.h>
#include <vtkRectilinearGrid.h>

#include "host_volume.h"

namespace mmrtm
{
namespace
{

// An image with `image`'s direction, the given geometry and `values` as its
// point scalars.
vtkSmartPointer<vtkImageData> MakeImage(
  vtkImageData* like, const int extent[6], const double origin[3], const double spacing[3], vtkDataArray* values)
{
  auto out = vtkSmartPointer<vtkImageData>::New();
  out->SetExtent(const_cast<int*>(extent));
  out->SetOrigin(origin[0], origin[1], origin[2]);
  out->SetSpacing(spacing[0], spacing[1], spacing[2]);
  if (like)
    out->SetDirectionMatrix(like->GetDirectionMatrix());
  out->GetPointData()->SetScalars(values);
  return out;
}

// `origin` moved by `steps` spacings along the image's axes (through its
// direction matrix).
void Shift(vtkImageData* image, const double steps[3], double origin[3])
{
  const double* s = image->GetSpacing();
  vtkMatrix3x3* d = image->GetDirectionMatrix();
  for (int r = 0; r < 3; ++r)
    for (int a = 0; a < 3; ++a)
      origin[r] += d->GetElement(r, a) * steps[a] * s[a];
}

// Cell scalars as point scalars at the cell centres.
vtkSmartPointer<vtkImageData> CellCentres(vtkImageData* image, vtkDataArray* cells)
{
  int extent[6];
  image->GetExtent(extent);
  double origin[3], half[3];
  image->GetOrigin(origin);
  for (int a = 0; a < 3; ++a)
  {
    const bool flat = extent[2 * a + 1] == extent[2 * a];
    half[a] = flat ? 0.0 : 0.5; // a flat axis has cells of its one point
    if (!flat)
      --extent[2 * a + 1];
  }
  Shift(image, half, origin);
  auto out = MakeImage(image, extent, origin, image->GetSpacing(), cells);
  if (out->GetNumberOfPoints() != cells->GetNumberOfTuples())
    throw InputError("the input's cell scalars hold " + std::to_string(cells->GetNumberOfTuples()) + " tuples for " +
      std::to_string(out->GetNumberOfPoints()) + " cells");
  return out;
}

// Each flat axis made two points half a spacing either side of the slice.
vtkSmartPointer<vtkImageData> Slab(vtkImageData* image, vtkDataArray* values)
{
  int extent[6], dims[3], out[3];
  image->GetExtent(extent);
  image->GetDimensions(dims);
  double origin[3], spacing[3], steps[3];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  for (int a = 0; a < 3; ++a)
  {
    const bool flat = dims[a] == 1;
    if (flat && spacing[a] == 0.0)
      spacing[a] = 1.0;
    steps[a] = flat ? -0.5 : 0.0;
    out[a] = flat ? 2 : dims[a];
    extent[2 * a + 1] = extent[2 * a] + out[a] - 1;
  }
  auto slab = MakeImage(image, extent, origin, spacing, nullptr);
  double shifted[3] = { origin[0], origin[1], origin[2] };
  Shift(slab, steps, shifted);
  slab->SetOrigin(shifted);
  vtkSmartPointer<vtkDataArray> copy = vtk::TakeSmartPointer(values->NewInstance());
  copy->SetName(values->GetName());
  copy->SetNumberOfComponents(values->GetNumberOfComponents());
  copy->SetNumberOfTuples((vtkIdType)out[0] * out[1] * out[2]);
  for (int k = 0; k < out[2]; ++k)
    for (int j = 0; j < out[1]; ++j)
      for (int i = 0; i < out[0]; ++i)
      {
        const vtkIdType from = std::min(i, dims[0] - 1) +
          (vtkIdType)dims[0] * (std::min(j, dims[1] - 1) + (vtkIdType)dims[1] * std::min(k, dims[2] - 1));
        copy->SetTuple(i + (vtkIdType)out[0] * (j + (vtkIdType)out[1] * k), from, values);
      }
  slab->GetPointData()->SetScalars(copy);
  return slab;
}

// One axis of a rectilinear grid on a uniform grid: for each new point the
// old cell it falls in and its fraction there.
struct Axis
{
  double origin = 0.0, spacing = 1.0;
  std::vector<int> cell;
  std::vector<double> t;
};

Axis UniformAxis(vtkDataArray* coordinates, const char* name)
{
  const vtkIdType n = coordinates->GetNumberOfTuples();
  std::vector<double> x((size_t)n);
  for (vtkIdType i = 0; i < n; ++i)
    x[i] = coordinates->GetComponent(i, 0);
  Axis axis;
  axis.origin = n ? x[0] : 0.0;
  if (n < 2)
  {
    axis.cell.assign(1, 0);
    axis.t.assign(1, 0.0);
    return axis;
  }
  double smallest = x[1] - x[0];
  for (vtkIdType i = 1; i < n; ++i)
  {
    if (!(x[i] > x[i - 1]))
      throw InputError(std::string("the vtkRectilinearGrid's ") + name + " coordinates are not ascending");
    smallest = std::min(smallest, x[i] - x[i - 1]);
  }
  const double length = x[n - 1] - x[0];
  const vtkIdType points =
    std::min<vtkIdType>((vtkIdType)std::llround(length / smallest) + 1, kMaxRefinement * (n - 1) + 1);
  axis.spacing = length / (double)(points - 1);
  for (vtkIdType p = 0; p < points; ++p)
  {
    const double at = x[0] + axis.spacing * (double)p;
    const int c = (int)std::clamp<vtkIdType>(std::upper_bound(x.begin(), x.end(), at) - x.begin() - 1, 0, n - 2);
    axis.cell.push_back(c);
    axis.t.push_back(std::clamp((at - x[c]) / (x[c + 1] - x[c]), 0.0, 1.0));
  }
  return axis;
}

vtkSmartPointer<vtkImageData> Resample(vtkRectilinearGrid* grid, vtkDataArray* values)
{
  int dims[3];
  grid->GetDimensions(dims);
  const std::array<Axis, 3> axes = { UniformAxis(grid->GetXCoordinates(), "x"),
    UniformAxis(grid->GetYCoordinates(), "y"), UniformAxis(grid->GetZCoordinates(), "z") };
  const int out[3] = { (int)axes[0].cell.size(), (int)axes[1].cell.size(), (int)axes[2].cell.size() };
  const int extent[6] = { 0, out[0] - 1, 0, out[1] - 1, 0, out[2] - 1 };
  const double origin[3] = { axes[0].origin, axes[1].origin, axes[2].origin };
  const double spacing[3] = { axes[0].spacing, axes[1].spacing, axes[2].spacing };
  const int components = values->GetNumberOfComponents();
  const bool integers = values->GetDataType() != VTK_FLOAT && values->GetDataType() != VTK_DOUBLE;
  vtkSmartPointer<vtkDataArray> resampled = vtk::TakeSmartPointer(values->NewInstance());
  resampled->SetName(values->GetName());
  resampled->SetNumberOfComponents(components);
  resampled->SetNumberOfTuples((vtkIdType)out[0] * out[1] * out[2]);
  auto index = [&](int i, int j, int k) { return i + (vtkIdType)dims[0] * (j + (vtkIdType)dims[1] * k); };
  for (int k = 0; k < out[2]; ++k)
    for (int j = 0; j < out[1]; ++j)
      for (int i = 0; i < out[0]; ++i)
      {
        const int c[3] = { axes[0].cell[i], axes[1].cell[j], axes[2].cell[k] };
        const double t[3] = { axes[0].t[i], axes[1].t[j], axes[2].t[k] };
        for (int m = 0; m < components; ++m)
        {
          double v = 0.0;
          for (int corner = 0; corner < 8; ++corner)
          {
            double w = 1.0;
            int at[3];
            for (int a = 0; a < 3; ++a)
            {
              const int up = (corner >> a) & 1;
              at[a] = std::min(c[a] + up, dims[a] - 1);
              w *= up ? t[a] : 1.0 - t[a];
            }
            if (w > 0.0)
              v += w * values->GetComponent(index(at[0], at[1], at[2]), m);
          }
          resampled->SetComponent(i + (vtkIdType)out[0] * (j + (vtkIdType)out[1] * k), m, integers ? std::round(v) : v);
        }
      }
  return MakeImage(nullptr, extent, origin, spacing, resampled);
}

} // namespace

TracedImage ImageForTracing(vtkDataSet* input, vtkDataArray* scalars, bool cellScalars)
{
  TracedImage traced;
  vtkSmartPointer<vtkImageData> image = vtkImageData::SafeDownCast(input);
  if (auto* grid = vtkRectilinearGrid::SafeDownCast(input))
  {
    if (cellScalars)
      throw InputError("cell scalars on a vtkRectilinearGrid are not supported (vtkCellDataToPointData converts them)");
    image = Resample(grid, scalars);
    scalars = image->GetPointData()->GetScalars();
    int dims[3];
    image->GetDimensions(dims);
    traced.Conversion = "the vtkRectilinearGrid was resampled onto a uniform grid of " + std::to_string(dims[0]) +
      " x " + std::to_string(dims[1]) + " x " + std::to_string(dims[2]) + " points";
  }
  else if (!image)
    throw InputError(std::string("the input is a ") + input->GetClassName() +
      "; the mapper renders a vtkImageData or a vtkRectilinearGrid");
  else if (cellScalars)
  {
    image = CellCentres(image, scalars);
    traced.Conversion = "cell scalars are rendered as point scalars at the cell centres";
  }
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] == 1 || dims[1] == 1 || dims[2] == 1)
  {
    image = Slab(image, scalars);
    scalars = image->GetPointData()->GetScalars();
    traced.Conversion +=
      std::string(traced.Conversion.empty() ? "" : "; ") + "a single slice is rendered as a slab one voxel thick";
  }
  if (image != input)
  {
    traced.Image = image;
    traced.Scalars = image->GetPointData()->GetScalars();
  }
  return traced;
}

} // namespace mmrtm
