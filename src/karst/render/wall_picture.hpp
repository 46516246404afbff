#pragma once
// The scene's walls as pictured by `karst render`: obstacles as solid concrete, containers as a
// shell of the walls' thickness around the space they hold, cut away on the camera's side. A run
// writes them into render.json (their shapes as the scene writes them), so a folder renders without
// its scene.
#include "karst/scene/geometry.hpp"

#include <nlohmann/json_fwd.hpp>

#include <string>
#include <vector>

namespace karst {

struct PicturedWall {
    Shape shape;
    bool container = false;
    Real thickness = 0;  ///< layers x spacing, m: the container shell's thickness
};

nlohmann::json walls_to_json(const std::vector<PicturedWall>& walls);
/// Throws nlohmann::json::exception on a malformed list (SceneError for an impossible shape).
std::vector<PicturedWall> walls_from_json(const nlohmann::json& j);

/// POV-Ray objects (CSG of box, sphere, cylinder) for the walls seen from `camera`, with their
/// materials.
std::string pov_walls(const std::vector<PicturedWall>& walls, const Vec3& camera);

}  // namespace karst
