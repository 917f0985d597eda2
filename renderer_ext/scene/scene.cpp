#include "scene/scene.h"

#include <cmath>

namespace wv {

void Scene::finalize() {
  std::vector<Box> boxes(prims.size());
  lights.clear();
  bound_radius = 0.0;
  for (size_t i = 0; i < prims.size(); ++i) {
    const Prim& p = prims[i];
    switch (p.kind) {
      case PrimKind::kSphere: boxes[i] = bounds(spheres[p.index]); break;
      case PrimKind::kQuad: boxes[i] = bounds(quads[p.index]); break;
      case PrimKind::kDisk: boxes[i] = bounds(disks[p.index]); break;
      default: boxes[i] = bounds(triangles[p.index]); break;
    }
    for (int c = 0; c < 8; ++c) {
      const V3 corner{(c & 1) ? boxes[i].hi.x : boxes[i].lo.x, (c & 2) ? boxes[i].hi.y : boxes[i].lo.y,
                      (c & 4) ? boxes[i].hi.z : boxes[i].lo.z};
      bound_radius = std::max(bound_radius, length(corner));
    }
    if (materials[p.material].emits() && p.kind != PrimKind::kTriangle)
      lights.push_back(int(i));
  }
  bvh.build(boxes);
  environment.stars.setup();
  environment_other.stars.setup();
}

}  // namespace wv
