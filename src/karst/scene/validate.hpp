#pragma once
// Checks a scene document against the schema table and fills in defaults.
#include <nlohmann/json.hpp>

namespace karst {

/// Validates `doc` in place against scene_schema(): unknown keys, missing required keys, wrong
/// types and out-of-range values throw SceneError naming the JSON path; absent keys that have a
/// default are inserted, so later code reads every key without fallbacks.
void validate_scene_document(nlohmann::json& doc);

}  // namespace karst
