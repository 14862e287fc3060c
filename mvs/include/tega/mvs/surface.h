#pragma once
// A watertight surface from an oriented point cloud: screened Poisson
// reconstruction (Open3D), trimmed where the points do not support it.

#include "tega/core/mesh.h"
#include "tega/mvs/point_cloud.h"

namespace tega::mvs {

struct SurfaceOptions {
  int poisson_depth = 9;
  double poisson_scale = 1.1;
  // Vertices whose Poisson density (point support) is below this quantile of all
  // vertex densities are removed, with their faces.
  double trim_density_quantile = 0.05;
  // Faces farther than this from every input point are removed (metres; 0 = off),
  // measured at their vertices: a face stays while one of its vertices is near a point.
  double trim_distance_m = 0.003;
  // Connected components with fewer faces than this share of the largest are removed.
  double min_component_share = 0.05;
  int threads = 0;  // trimming and orientation; 0: one per hardware thread
  // Open3D 0.16's Poisson splats the points on several threads with a race:
  // now and then it crashes (a segfault in FEMTree::_splatPointData, more
  // often on a busy machine) and its meshes differ from run to run. On one
  // thread it is neither, and at depth 8 about as fast (docs/mvs.md).
  int poisson_threads = 1;

  template <class V>
  void visit(V& v) {
    v("poisson_depth", poisson_depth, "Octree depth of the screened Poisson reconstruction (finer with each level).");
    v("poisson_scale", poisson_scale, "Poisson bounding cube relative to the points' bounding box.");
    v("trim_density_quantile", trim_density_quantile,
      "Remove vertices whose Poisson density is below this quantile (unsupported surface).");
    v("trim_distance_m", trim_distance_m, "Remove faces farther than this from every point, in metres (0: off).");
    v("min_component_share", min_component_share,
      "Remove connected components smaller than this share of the largest (in faces).");
    v("threads", threads, "Worker threads of the trimming and orientation (0: one per hardware thread).");
    v("poisson_threads", poisson_threads,
      "Threads of Open3D's Poisson solver (0: one per hardware thread). More than one can crash now and then "
      "(a race in Open3D 0.16's PoissonRecon) and makes the mesh differ from run to run.");
  }
};

// Faces wind counter-clockwise seen from outside, the side the cloud's
// normals point to. Throws tega::Error when the cloud is empty or has no normals.
Mesh reconstruct_surface(const OrientedPointCloud& cloud, const SurfaceOptions& options);

}  // namespace tega::mvs
