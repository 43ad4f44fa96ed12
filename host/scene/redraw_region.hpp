// scene/redraw_region.hpp — which pixels a moving body can change, so a frame where
// only bodies moved redraws those (kiln/pass.hpp, REDRAWING PART OF THE PICTURE).
//
// A body changes the picture where it was and where it is, where its shadow falls, and
// the light nearby (what it bounces onto and hides from its neighbours). The first and
// the last are its bounding sphere grown by `reach`; the shadow is bounded exactly
// enough: every line from a point of the lamp's ball through a point of the body's
// sphere runs, beyond the body, inside the cone tangent to both balls whose apex lies
// between them (the internal homothety centre), so the shadow on anything in the room
// lies in that cone clipped to the room's box. What a body changes far away (a little
// of everyone's bounce light) is left to the rows refreshed band by band.
#pragma once

#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "kiln/pass.hpp"

namespace kiln::scene {

struct RedrawView {
    glm::mat4 viewProj{1.0f};
    int width = 0, height = 0;
    glm::vec3 lampCentre{0.0f};
    float lampRadius = 0.0f;
    glm::vec3 roomMin{-1.0f}, roomMax{1.0f};  // everything a shadow can fall on
};

// How far beyond a body its presence changes the light nearby (metres), and how many
// pixels every edge is grown by (the shadow's filter, bloom's blur, rounding).
struct RedrawReach {
    float metres = 0.25f;
    int pixels = 16;
};

// The pixel rectangle (clamped to the picture) covering what bodies moving through
// `spheres` (xyz centre, w radius: where each was and where it is) change directly, or
// nullopt when one of them or its shadow reaches behind the camera (redraw everything).
std::optional<PixelRect> changedPixels(const std::vector<glm::vec4>& spheres, const RedrawView& view,
                                       const RedrawReach& reach = {});

// Band `index` (mod kRedrawBands) of the picture's rows, across its whole width.
PixelRect redrawBand(int index, int width, int height);

}  // namespace kiln::scene
