// scene/punctual.hpp — the placed models' punctual lights as the frame uniforms carry
// them (GpuFrame::punctual), with the shadow atlas tile and matrix of each of the first
// kMaxShadowedLights that cast shadows.
#pragma once

#include <vector>

#include "kiln/scene_view.hpp"
#include "model/model.hpp"

namespace kiln::scene {

// A light's view of the scene for its shadow tile: a directional light's orthographic
// view of the scene's bounding sphere, a spot light's perspective over its cone (to its
// range, or to the far side of the bounds). Point lights cast no shadow (none is made).
bool shadowViewProj(const model::Light&, glm::vec3 sceneMin, glm::vec3 sceneMax, glm::mat4& out);

// Fills frame.punctual and frame.punctualCount from `lights` (at most
// kMaxPunctualLights; the caller warns about the rest).
void packPunctualLights(const std::vector<model::Light>& lights, glm::vec3 sceneMin, glm::vec3 sceneMax, GpuFrame& frame);

}  // namespace kiln::scene
