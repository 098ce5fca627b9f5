// An open city: an 8 × 8 grid of plots on a street grid, each plot a kerbed
// pavement slab carrying one of five office blocks, lit by a low sun and the sky
// (`bake --sky`). The blocks are instances: five meshes, each placed on many nodes
// (turned by quarter turns), so the baker gives every instance its own lightmap
// rectangle over a shared TEXCOORD_1 layout. A block's facades are cut by vertical
// window bays; each bay is a recess whose back is a profile of spandrels, sill
// ledges, transoms and window panes (some lit: emissive), so the triangle count comes from
// modelled detail rather than subdivision.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "sample_scenes.h"

namespace exitance::samples {
namespace {

constexpr int kPlotsPerSide = 8;
constexpr float kPlotSize = 26.0f, kStreetWidth = 10.0f;
constexpr float kPlotPitch = kPlotSize + kStreetWidth;
constexpr float kKerbHeight = 0.15f;

// Vertical layout of a facade: a plinth band, the storeys, a parapet band.
constexpr float kPlinth = 0.6f, kStoreyHeight = 3.2f, kParapet = 0.6f;
// Depths behind the facade plane of the bay's surfaces.
constexpr float kSpandrelDepth = 0.3f, kLedgeDepth = 0.2f, kPaneDepth = 0.45f, kTransomDepth = 0.4f;
// Heights within a storey.
constexpr float kLedgeBottom = 0.82f, kSillHeight = 0.9f, kTransomBottom = 2.1f, kTransomTop = 2.18f,
                kHeadHeight = 2.6f;

struct Materials {
  MaterialId facade, trim, roof, litPane, darkPane, pavement, asphalt, plant;
};

struct Variant {
  const char* name;
  float width, depth;        // footprint along local x and z
  int storeys;
  int baysAlongWidth, baysAlongDepth;
  float bayFraction;         // share of each bay's width that is recess
  bool plantRoom;            // a box on the roof
};

constexpr Variant kVariants[] = {
    {"Slab", 24.0f, 14.0f, 8, 7, 4, 0.55f, false},
    {"Tower", 16.0f, 16.0f, 20, 4, 4, 0.6f, true},
    {"Block", 22.0f, 22.0f, 6, 6, 6, 0.5f, false},
    {"Midrise", 20.0f, 12.0f, 12, 5, 3, 0.55f, true},
    {"Narrow", 10.0f, 20.0f, 15, 2, 5, 0.6f, false},
};

float facadeHeight(const Variant& v) { return kPlinth + float(v.storeys) * kStoreyHeight + kParapet; }

// Deterministic pseudo-random bits (no library distribution, same everywhere).
std::uint32_t mix(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// A point of a bay's profile: depth behind the facade plane and height above the ground.
struct ProfilePoint {
  float depth, height;
};

// The bay's back surface from the plinth up to the parapet, as seen in section.
std::vector<ProfilePoint> bayProfile(int storeys) {
  const float bottom = kPlinth, top = kPlinth + float(storeys) * kStoreyHeight;
  std::vector<ProfilePoint> points{{0.0f, bottom}, {kSpandrelDepth, bottom}};
  for (int storey = 0; storey < storeys; ++storey) {
    const float y = bottom + float(storey) * kStoreyHeight;
    points.push_back({kSpandrelDepth, y + kLedgeBottom});  // spandrel
    points.push_back({kLedgeDepth, y + kLedgeBottom});     // ledge underside
    points.push_back({kLedgeDepth, y + kSillHeight});      // ledge front
    points.push_back({kPaneDepth, y + kSillHeight});       // sill
    points.push_back({kPaneDepth, y + kTransomBottom});    // lower pane
    points.push_back({kTransomDepth, y + kTransomBottom}); // transom underside
    points.push_back({kTransomDepth, y + kTransomTop});    // transom front
    points.push_back({kPaneDepth, y + kTransomTop});       // transom top
    points.push_back({kPaneDepth, y + kHeadHeight});       // upper pane
    points.push_back({kSpandrelDepth, y + kHeadHeight});   // head
  }
  points.push_back({kSpandrelDepth, top});
  points.push_back({0.0f, top});
  return points;
}

// One facade: its plane's lower-left corner seen from outside, the unit directions
// along it and out of the building, and its width.
struct Facade {
  Vec3 corner, along, outward;
  float width;
  int bays;
};

void addFacade(MeshBuilder& mesh, const Materials& materials, const Variant& variant, const Facade& facade,
               std::uint32_t seed) {
  const Vec3 up{0, 1, 0};
  const float height = facadeHeight(variant);
  const float bottom = kPlinth, top = kPlinth + float(variant.storeys) * kStoreyHeight;
  const float bay = facade.width / float(facade.bays), opening = bay * variant.bayFraction;

  // Cuts along the facade: pier, opening, pier, ... so pieces share their corners.
  std::vector<float> cuts{0.0f};
  for (int b = 0; b < facade.bays; ++b) {
    cuts.push_back(float(b) * bay + (bay - opening) / 2);
    cuts.push_back(float(b) * bay + (bay + opening) / 2);
  }
  cuts.push_back(facade.width);
  const float rows[] = {0.0f, bottom, top, height};

  auto onWall = [&](size_t c, int r) { return facade.corner + facade.along * cuts[c] + up * rows[r]; };
  std::vector<PanelPiece> wall;
  for (size_t c = 0; c + 1 < cuts.size(); ++c)
    for (int r = 0; r < 3; ++r) {
      const bool isOpening = c % 2 == 1 && r == 1;
      if (isOpening) continue;
      wall.push_back({{onWall(c, r), onWall(c + 1, r), onWall(c + 1, r + 1), onWall(c, r + 1)},
                      cuts[c], rows[r], cuts[c + 1], rows[r + 1], materials.facade});
    }
  mesh.addPanel(std::move(wall));

  const std::vector<ProfilePoint> profile = bayProfile(variant.storeys);
  auto at = [&](float alongFacade, ProfilePoint p) {
    return facade.corner + facade.along * alongFacade - facade.outward * p.depth + up * p.height;
  };
  for (int b = 0; b < facade.bays; ++b) {
    const float left = cuts[size_t(2 * b + 1)], right = cuts[size_t(2 * b + 2)];

    // The bay's back: the profile swept across the opening, unfolded along its length.
    std::vector<PanelPiece> back;
    float unfolded = 0.0f;
    for (size_t i = 0; i + 1 < profile.size(); ++i) {
      const ProfilePoint low = profile[i], high = profile[i + 1];
      const float next = unfolded + std::abs(high.depth - low.depth) + std::abs(high.height - low.height);
      const bool pane = low.depth == kPaneDepth && high.depth == kPaneDepth;
      const int storey = int((low.height - bottom) / kStoreyHeight);
      const bool lit = mix(seed ^ mix(std::uint32_t(b * 131 + storey))) % 100 < 35;
      back.push_back({{at(left, low), at(right, low), at(right, high), at(left, high)},
                      0.0f,
                      unfolded,
                      right - left,
                      next,
                      pane ? (lit ? materials.litPane : materials.darkPane) : materials.trim});
      unfolded = next;
    }
    mesh.addPanel(std::move(back));

    // The two jambs: between the facade plane and the profile, one rectangle per
    // vertical stretch of the profile, all sharing their edge on the facade plane.
    std::vector<PanelPiece> leftJamb, rightJamb;
    for (size_t i = 0; i + 1 < profile.size(); ++i) {
      const ProfilePoint low = profile[i], high = profile[i + 1];
      if (low.depth != high.depth || low.depth == 0.0f) continue;
      const ProfilePoint lowFront{0.0f, low.height}, highFront{0.0f, high.height};
      const float s0 = low.height - bottom, s1 = high.height - bottom, t0 = kPaneDepth - low.depth;
      // Faces +along: s up the jamb, t out towards the facade plane.
      leftJamb.push_back({{at(left, low), at(left, high), at(left, highFront), at(left, lowFront)},
                          s0, t0, s1, kPaneDepth, materials.trim});
      // Faces -along: s out towards the facade plane, t up the jamb.
      rightJamb.push_back({{at(right, low), at(right, lowFront), at(right, highFront), at(right, high)},
                           t0, s0, kPaneDepth, s1, materials.trim});
    }
    mesh.addPanel(std::move(leftJamb));
    mesh.addPanel(std::move(rightJamb));
  }
}

// A horizontal grid of rectangles facing up, cut at `xs` and `zs` (increasing), the cells
// for which `open(i, j)` holds left out: one chart whose shared corners are exact.
template <typename IsOpen>
std::vector<PanelPiece> floorWithHoles(const std::vector<float>& xs, const std::vector<float>& zs, float y,
                                       MaterialId material, IsOpen open) {
  // s runs along +x and t along -z, so cross(s, t) points up.
  const float sOrigin = xs.front(), tOrigin = zs.back();
  auto corner = [&](size_t i, size_t j) { return Vec3{xs[i], y, zs[j]}; };
  std::vector<PanelPiece> pieces;
  for (size_t i = 0; i + 1 < xs.size(); ++i)
    for (size_t j = 0; j + 1 < zs.size(); ++j) {
      if (open(i, j)) continue;
      pieces.push_back({{corner(i, j + 1), corner(i + 1, j + 1), corner(i + 1, j), corner(i, j)},
                        xs[i] - sOrigin, tOrigin - zs[j + 1], xs[i + 1] - sOrigin, tOrigin - zs[j], material});
    }
  return pieces;
}

// A block on its plot: a kerbed pavement slab around the building's footprint, then
// the building standing on it.
MeshBuilder buildBlock(const Materials& materials, const Variant& variant, std::uint32_t seed) {
  MeshBuilder mesh;
  const float w = variant.width / 2, d = variant.depth / 2, p = kPlotSize / 2;
  mesh.addPanel(floorWithHoles({-p, -w, w, p}, {-p, -d, d, p}, kKerbHeight, materials.pavement,
                               [](size_t i, size_t j) { return i == 1 && j == 1; }));
  mesh.addBox({.center = {0, kKerbHeight / 2, 0}, .size = {kPlotSize, kKerbHeight, kPlotSize}}, materials.pavement,
              FaceDirection::Outward, BoxFace::NegX | BoxFace::PosX | BoxFace::NegZ | BoxFace::PosZ);

  const float base = kKerbHeight;
  const Facade facades[] = {
      {{-w, base, d}, {1, 0, 0}, {0, 0, 1}, variant.width, variant.baysAlongWidth},
      {{w, base, -d}, {-1, 0, 0}, {0, 0, -1}, variant.width, variant.baysAlongWidth},
      {{w, base, d}, {0, 0, -1}, {1, 0, 0}, variant.depth, variant.baysAlongDepth},
      {{-w, base, -d}, {0, 0, 1}, {-1, 0, 0}, variant.depth, variant.baysAlongDepth},
  };
  for (int f = 0; f < 4; ++f) addFacade(mesh, materials, variant, facades[f], mix(seed * 4 + std::uint32_t(f)));

  const float height = base + facadeHeight(variant);
  if (!variant.plantRoom) {
    mesh.addQuad(Quad::axisAligned({-w, height, -d}, {w, height, d}, {0, 1, 0}), materials.roof);
    return mesh;
  }
  // The roof leaves out the plant room's footprint, which would never be lit.
  const float x0 = -0.15f * w, x1 = 0.65f * w, z0 = -0.5f * d, z1 = 0.1f * d;
  mesh.addPanel(floorWithHoles({-w, x0, x1, w}, {-d, z0, z1, d}, height, materials.roof,
                               [](size_t i, size_t j) { return i == 1 && j == 1; }));
  mesh.addBox({.center = {(x0 + x1) / 2, height + 1.5f, (z0 + z1) / 2}, .size = {x1 - x0, 3.0f, z1 - z0}},
              materials.plant, FaceDirection::Outward, BoxFace::AllButBottom);
  return mesh;
}

}  // namespace

void buildOpenCity(SceneBuilder& scene) {
  const Materials materials{
      .facade = scene.addMaterial({.name = "Facade", .baseColor = {0.62f, 0.58f, 0.52f}}),
      .trim = scene.addMaterial({.name = "Trim", .baseColor = {0.45f, 0.45f, 0.47f}}),
      .roof = scene.addMaterial({.name = "Roof", .baseColor = {0.25f, 0.25f, 0.27f}}),
      .litPane = scene.addMaterial({.name = "LitWindow",
                                    .baseColor = {0.05f, 0.05f, 0.05f},
                                    .emissiveColor = {1.0f, 0.8f, 0.55f},
                                    .emissiveStrength = 4.0f}),
      .darkPane = scene.addMaterial({.name = "DarkWindow", .baseColor = {0.04f, 0.05f, 0.06f}}),
      .pavement = scene.addMaterial({.name = "Pavement", .baseColor = {0.50f, 0.48f, 0.45f}}),
      .asphalt = scene.addMaterial({.name = "Asphalt", .baseColor = {0.12f, 0.12f, 0.13f}}),
      .plant = scene.addMaterial({.name = "PlantRoom", .baseColor = {0.55f, 0.55f, 0.55f}}),
  };

  std::vector<int> blocks;
  for (std::uint32_t v = 0; v < std::size(kVariants); ++v)
    blocks.push_back(scene.addMesh(kVariants[v].name, buildBlock(materials, kVariants[v], 1000u + v)));

  // Streets: the ground between the plots (none under them, where it would never be lit).
  std::vector<float> cuts;
  const float half = float(kPlotsPerSide) * kPlotPitch / 2 + kStreetWidth / 2;
  auto plotCenter = [](int k) { return (float(k) - float(kPlotsPerSide - 1) / 2) * kPlotPitch; };
  cuts.push_back(-half);
  for (int k = 0; k < kPlotsPerSide; ++k) {
    cuts.push_back(plotCenter(k) - kPlotSize / 2);
    cuts.push_back(plotCenter(k) + kPlotSize / 2);
  }
  cuts.push_back(half);
  MeshBuilder streets;
  streets.addPanel(floorWithHoles(cuts, cuts, 0.0f, materials.asphalt,
                                  [](size_t i, size_t j) { return i % 2 == 1 && j % 2 == 1; }));
  scene.addMeshNode("Streets", streets);

  for (int row = 0; row < kPlotsPerSide; ++row)
    for (int column = 0; column < kPlotsPerSide; ++column) {
      const Vec3 center{plotCenter(column), 0.0f, plotCenter(row)};
      const std::uint32_t pick = mix(std::uint32_t(row * kPlotsPerSide + column) + 77u);
      const size_t variant = pick % std::size(kVariants);
      const float yaw = float((pick >> 8) % 4) * std::numbers::pi_v<float> / 2;
      scene.addInstance(std::string(kVariants[variant].name) + "_" + std::to_string(row) + "_" + std::to_string(column),
                        blocks[variant], center, yaw);
    }

  // Sun 35° above the horizon from azimuth 35° (off every axis), as in the courtyard.
  const float elevation = 35.0f * std::numbers::pi_v<float> / 180.0f;
  const float azimuth = 35.0f * std::numbers::pi_v<float> / 180.0f;
  const Vec3 towardsSun{std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                        std::cos(elevation) * std::cos(azimuth)};
  scene.addDirectionalLight({.name = "Sun", .direction = -towardsSun, .color = {1.0f, 0.95f, 0.85f}, .intensity = 3.0f});
}

}  // namespace exitance::samples
