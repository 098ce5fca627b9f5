#include <nlohmann/json.hpp>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/format_error.h"

namespace exitance::formats {
namespace {

using nlohmann::json;

template <typename T, size_t N>
json array_json(const std::array<T, N>& values) {
  json list = json::array();
  for (const T& v : values) list.push_back(v);
  return list;
}

json settings_json(const BakeSettings& s) {
  json j = {{"integrator", s.integrator},
            {"spp", s.spp},
            {"time_budget_seconds", s.time_budget_seconds},
            {"target_error", s.target_error},
            {"adaptive", s.adaptive},
            {"sampler", s.sampler},
            {"first_bounce", s.first_bounce},
            {"bounces", s.bounces},
            {"seed", s.seed},
            {"texel_density", s.texel_density},
            {"max_page", s.max_page},
            {"padding", s.padding},
            {"lightmap_uv", s.lightmap_uv_generate ? json("generate") : json(s.lightmap_uv)},
            {"generated_uv_meshes", s.generated_uv_meshes},
            {"russian_roulette_start", s.russian_roulette_start},
            {"safety_bounce_cap", s.safety_bounce_cap},
            {"sky", s.sky},
            {"probes", s.probe_spacing ? json(*s.probe_spacing) : json("none")},
            {"probe_spp", s.probe_spp},
            {"probe_dering_window", s.probe_dering_window},
            {"voxel_resolution", s.voxel_resolution ? json(*s.voxel_resolution) : json("none")}};
  if (!s.backend.empty()) j["backend"] = s.backend;
  if (s.directional != "off") j["directional"] = s.directional;
  return j;
}

json probes_json(const ProbeGridInfo& p) {
  json j = {{"file", p.file},
            {"origin", array_json(p.origin)},
            {"spacing", array_json(p.spacing)},
            {"counts", array_json(p.counts)},
            {"sh_order", p.sh_order}};
  if (p.placement) {
    j["valid"] = p.placement->valid;
    j["moved"] = p.placement->moved;
    j["invalid"] = p.placement->invalid;
    j["skipped"] = p.placement->skipped;
  }
  return j;
}

json svo_json(const SvoInfo& s) {
  json j = {{"file", s.file},
            {"bounds", {array_json(s.bounds_min), array_json(s.bounds_max)}},
            {"depth", s.depth},
            {"units", "radiant_exitance"}};
  if (s.nodes) j["nodes"] = s.nodes;
  if (!s.vdb.empty()) j["vdb"] = s.vdb;
  if (!s.vdb_note.empty()) j["vdb_note"] = s.vdb_note;
  return j;
}

json preview_json(const PreviewInfo& p) {
  json j = {{"pages", p.pages}, {"views", json::array()}};
  for (const PreviewViewInfo& v : p.views)
    j["views"].push_back({{"file", v.file},
                          {"camera", v.camera},
                          {"look_from", array_json(v.look_from)},
                          {"look_at", array_json(v.look_at)},
                          {"up", array_json(v.up)},
                          {"yfov", v.yfov},
                          {"width", v.width},
                          {"height", v.height}});
  if (!p.views_skipped.empty()) j["views_skipped"] = p.views_skipped;
  return j;
}

json free_form(const std::string& text, const char* key) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw FormatError(std::string("manifest.json: ") + key + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw FormatError(std::string("manifest.json: ") + key + ": expected an object, got " + j.type_name());
  return j;
}

}  // namespace

std::string write_bundle_manifest(const BundleManifest& m) {
  json root;
  root["format_version"] = m.format_version;
  if (!m.generator.empty()) root["generator"] = m.generator;
  if (m.input) root["input"] = {{"file", m.input->file}, {"sha256", m.input->sha256}};
  root["units"] = {{"lightmap", "irradiance_over_pi"}, {"probes", "incident_radiance_sh_l2"}, {"length", "scene"}};
  if (m.settings) root["settings"] = settings_json(*m.settings);
  root["pages"] = json::array();
  for (const PageInfo& page : m.pages)
    root["pages"].push_back({{"file", page.file}, {"width", page.width}, {"height", page.height}, {"channels", page.channels}});
  root["instances"] = json::array();
  for (const InstanceInfo& i : m.instances) {
    json j = {{"node", i.node}, {"name", i.name}, {"mesh", i.mesh}, {"page", i.page}, {"scale_offset", array_json(i.scale_offset)}};
    if (i.rect) j["rect"] = array_json(*i.rect);
    root["instances"].push_back(j);
  }
  if (m.probes) root["probes"] = probes_json(*m.probes);
  if (m.svo) root["svo"] = svo_json(*m.svo);
  if (m.scene) {
    if (m.scene->file.empty())
      root["scene"] = {{"skipped", m.scene->skipped}};
    else
      root["scene"] = {{"file", m.scene->file}, {"format_version", m.scene->format_version}, {"bytes", m.scene->bytes}};
  }
  if (m.preview) root["preview"] = preview_json(*m.preview);
  if (m.light_layers)
    root["light_layers"] = {{"count", m.light_layers->count},
                            {"punctual", m.light_layers->punctual},
                            {"files", m.light_layers->files},
                            {"units", "irradiance_over_pi"}};
  if (!m.stats_json.empty()) root["stats"] = free_form(m.stats_json, "stats");
  if (!m.relight_json.empty()) root["relight"] = free_form(m.relight_json, "relight");

  std::string text = root.dump(2) + "\n";
  parse_bundle_manifest(text, "manifest.json (as written)");  // one schema: what is written can be read
  return text;
}

}  // namespace exitance::formats
