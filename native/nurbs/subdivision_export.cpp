#include "nurbs/subdivision_export.h"

#include "nurbs/density_map.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

constexpr int kMaxLevel = 6;

/// A refined vertex: position and image coordinates, in the form PrimvarRefiner expects.
struct NetVertex {
  double x = 0, y = 0, z = 0, s = 0, t = 0;
  void Clear(void* = nullptr) { x = y = z = s = t = 0.0; }
  void AddWithWeight(const NetVertex& v, float w) {
    x += w * v.x;
    y += w * v.y;
    z += w * v.z;
    s += w * v.s;
    t += w * v.t;
  }
};

void fail(const std::string& message) { throw std::invalid_argument(message); }

}  // namespace

void SubdivisionParams::validate() const {
  if (level < 0 || level > kMaxLevel) {
    std::ostringstream s;
    s << "level must be in [0, " << kMaxLevel << "] (got " << level << ")";
    fail(s.str());
  }
}

SubdividedMesh subdivideControlNet(const std::vector<glm::vec4>& controlPoints, int nu, int nv,
                                   const SubdivisionParams& params,
                                   const std::vector<float>& densityImage, int densityWidth,
                                   int densityHeight) {
  params.validate();
  if (nu < 2 || nv < 2) {
    std::ostringstream s;
    s << "nu and nv must be at least 2 (got " << nu << ", " << nv << ")";
    fail(s.str());
  }
  if (controlPoints.size() != std::size_t(nu) * std::size_t(nv)) {
    std::ostringstream s;
    s << "control_points must hold nu * nv = " << std::size_t(nu) * std::size_t(nv)
      << " points (got " << controlPoints.size() << ")";
    fail(s.str());
  }
  for (const glm::vec4& p : controlPoints)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      fail("control_points must be finite");
  const bool withDensity = !densityImage.empty();
  int rateU = 0, rateV = 0;
  if (withDensity) {
    // The image must be a density map of this net: width = (nu-1)(k_u+1)+1, height likewise.
    if (densityWidth < nu || densityHeight < nv || (densityWidth - 1) % (nu - 1) != 0 ||
        (densityHeight - 1) % (nv - 1) != 0 ||
        densityImage.size() != std::size_t(densityWidth) * std::size_t(densityHeight)) {
      std::ostringstream s;
      s << "density must be a map of shape ((nv-1)(k_v+1)+1, (nu-1)(k_u+1)+1) for nu = " << nu
        << ", nv = " << nv << " (got " << densityHeight << " x " << densityWidth << ")";
      fail(s.str());
    }
    rateU = (densityWidth - 1) / (nu - 1) - 1;  // k_u
    rateV = (densityHeight - 1) / (nv - 1) - 1;  // k_v
  }

  // Base mesh: one quad per cell of the control grid, counter-clockwise seen from ∂u × ∂v.
  const int faces = (nu - 1) * (nv - 1);
  std::vector<int> vertsPerFace(std::size_t(faces), 4);
  std::vector<int> faceVerts;
  faceVerts.reserve(std::size_t(faces) * 4);
  for (int v = 0; v + 1 < nv; ++v)
    for (int u = 0; u + 1 < nu; ++u) {
      const int a = v * nu + u;
      faceVerts.insert(faceVerts.end(), {a, a + 1, a + nu + 1, a + nu});
    }
  Far::TopologyDescriptor desc;
  desc.numVertices = nu * nv;
  desc.numFaces = faces;
  desc.numVertsPerFace = vertsPerFace.data();
  desc.vertIndicesPerFace = faceVerts.data();
  Sdc::Options options;
  options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, options)));
  if (!refiner) throw std::runtime_error("OpenSubdiv could not build the control net topology");
  Far::TopologyRefiner::UniformOptions uniform(params.level);
  uniform.fullTopologyInLastLevel = true;  // PrimvarRefiner::Limit needs it
  refiner->RefineUniform(uniform);

  std::vector<NetVertex> current(std::size_t(nu) * std::size_t(nv));
  for (int v = 0; v < nv; ++v)
    for (int u = 0; u < nu; ++u) {
      const glm::vec4& p = controlPoints[std::size_t(v) * nu + u];
      NetVertex& q = current[std::size_t(v) * nu + u];
      q.x = p.x;
      q.y = p.y;
      q.z = p.z;
      q.s = double(u) * (rateU + 1);  // image column of control point u
      q.t = double(v) * (rateV + 1);  // image row of control point v
    }
  Far::PrimvarRefiner primvar(*refiner);
  for (int level = 1; level <= params.level; ++level) {
    std::vector<NetVertex> next(std::size_t(refiner->GetLevel(level).GetNumVertices()));
    NetVertex* dst = next.data();
    primvar.Interpolate(level, current.data(), dst);
    current.swap(next);
  }
  if (params.limit) {
    std::vector<NetVertex> limit(current.size());
    NetVertex* dst = limit.data();
    primvar.Limit(current.data(), dst);
    // Image coordinates stay the refined ones: the limit moves positions only.
    for (std::size_t n = 0; n < limit.size(); ++n) {
      limit[n].s = current[n].s;
      limit[n].t = current[n].t;
    }
    current.swap(limit);
  }

  SubdividedMesh mesh;
  mesh.vertices.resize(current.size());
  for (std::size_t n = 0; n < current.size(); ++n)
    mesh.vertices[n] = glm::vec3(float(current[n].x), float(current[n].y), float(current[n].z));
  const Far::TopologyLevel& last = refiner->GetLevel(params.level);
  mesh.quads.resize(std::size_t(last.GetNumFaces()));
  for (int f = 0; f < last.GetNumFaces(); ++f) {
    const Far::ConstIndexArray fv = last.GetFaceVertices(f);
    if (fv.size() != 4) throw std::runtime_error("OpenSubdiv produced a non-quad face");
    mesh.quads[std::size_t(f)] = glm::ivec4(fv[0], fv[1], fv[2], fv[3]);
  }
  if (withDensity) {
    mesh.density.resize(current.size());
    for (std::size_t n = 0; n < current.size(); ++n)
      mesh.density[n] =
          densityImageValue(densityImage, densityWidth, densityHeight, current[n].s, current[n].t);
  }
  return mesh;
}

}  // namespace plume
