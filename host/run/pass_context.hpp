// run/pass_context.hpp — the PassContext a pass sees during execute(): its bound
// inputs (or their fallbacks), outputs and internal textures by declared name, its
// parameters, the scene, programs through its cache, framebuffers over its own
// textures, and the draw helpers. One per pass per frame, on the stack.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "graph/plan.hpp"
#include "kiln/pass.hpp"
#include "run/pass_slot.hpp"

namespace kiln::run {

// What drawScene() draws: the host's scene geometry (host/scene implements it).
class SceneDraw {
public:
    virtual void draw(const DrawFilter&) const = 0;
    // Binds the instance buffer at kInstanceBinding (every pass may read it).
    virtual void bindInstances() const = 0;

protected:
    ~SceneDraw() = default;
};

// What every pass of a frame shares.
struct FrameResources {
    const std::vector<std::unique_ptr<PassSlot>>& slots;  // parallel to the plan's passes
    const FallbackTextures& fallbacks;
    const ShaderLibrary& shaders;
    const SceneDraw& scene;
    GLuint emptyVao;
    bool readEverything = false;  // every output counts as read (Runtime::readEverything)
};

class HostPassContext final : public PassContext {
public:
    HostPassContext(const FrameResources& shared, PassSlot& slot, const graph::PlannedPass& planned,
                    const SceneView& view, const FrameInfo& frame)
        : shared_(shared), slot_(slot), planned_(planned), view_(view), frame_(frame) {}

    // This run is one that an earlier keepRunning asked for (nothing else changed).
    void markSettling() { settling_ = true; }

    const TextureRef& input(std::string_view slot) const override;
    bool isBound(std::string_view slot) const override;
    const TextureRef& output(std::string_view name) const override { return texture(name, false); }
    const TextureRef& internal(std::string_view name) const override { return texture(name, true); }
    const ParamValue& param(std::string_view name) const override;
    const SceneView& scene() const override { return view_; }
    const FrameInfo& frame() const override { return frame_; }

    GLuint program(const ProgramDesc& desc) override;
    GLuint framebuffer(std::initializer_list<std::string_view> colorTargets, std::string_view depthTarget,
                       int mipLevel) override;
    void drawFullscreenTriangle() override;
    void drawScene(const DrawFilter& filter) override { shared_.scene.draw(filter); }
    void nothingToDo(std::string_view reason) override { nothing_ = std::string(reason); }
    void fail(std::string_view message) override;
    void keepRunning(int frames, std::string_view reason) override;
    bool isRead(std::string_view output) const override;

    bool failed() const { return failed_; }
    const std::optional<std::string>& nothing() const { return nothing_; }

private:
    const TextureRef& texture(std::string_view name, bool internal) const;
    const TextureRef& ownTexture(std::string_view name) const;
    const TextureRef& missing(const char* what, std::string_view name) const;

    const FrameResources& shared_;
    PassSlot& slot_;
    const graph::PlannedPass& planned_;
    const SceneView& view_;
    const FrameInfo& frame_;
    // The accessors are const (a pass reads through them) but report misuse.
    mutable bool failed_ = false;
    bool settling_ = false;
    std::optional<std::string> nothing_;
};

}  // namespace kiln::run
