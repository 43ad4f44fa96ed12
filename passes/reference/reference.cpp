// reference — the ground truth the rest is measured against: a progressive
// path tracer over the scene — the placed meshes' triangles through the host's BVH
// (SceneView::rayMeshes), and the shapes that are exact as they are (walls as planes,
// marbles, fireballs and particles as spheres, tumblers as round cones, the lamp as the
// sphere below the ceiling) — with the rasterizer's materials and every light. The shader
// (shaders/reference/path.comp) says how it samples.
//
// Outputs (RGBA32F, rgb = the running mean, a = paths per pixel so far):
//   radiance  linear HDR radiance, before bloom and tonemapping (compare composite.hdr)
//   direct    emission seen by the camera plus the lamp's light on the first surface:
//             what composite computes directly; radiance − direct is the indirect part
// and (R32F) rays: the rays traced for each pixel so far — path segments and shadow rays —
// the reference's cost, per pixel (exact while under 2²⁴ a pixel).
//
// A frame dispatches the picture in bands of rows until its paths are added or its
// `budget_ms` is spent; the next frame goes on from the band where it stopped.
//
// It accumulates while nothing it reads changes (the scene's geometry, the lamp, the
// camera, its own estimator parameters, its output textures) and starts over when
// anything does; at `max_samples` it stops (nothing to do). Same seed and settings,
// same image, bit for bit.
#include <algorithm>
#include <chrono>

#include <kiln/hash.hpp>
#include <kiln/pass.hpp>

namespace {

class Reference final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "radiance", .format = Format::RGBA32F, .doc = "mean radiance; a = samples per pixel"})
            .output({.name = "direct", .format = Format::RGBA32F,
                     .doc = "emission + the lamp's direct light on the first surface; a = samples"})
            .output({.name = "rays", .format = Format::R32F,
                     .doc = "rays traced for the pixel so far (path segments and shadow rays): where the cost is"})
            .param(intParam("samples_per_frame", 1, 1, 256, "paths per pixel added each frame"))
            .param(intParam("max_samples", 4096, 1, 1 << 20, "stop accumulating at this many paths per pixel"))
            .param(intParam("max_bounces", 16, 1, 256, "path length limit (Russian roulette ends most paths sooner)"))
            .param(intParam("roulette_start", 3, 0, 256, "bounce from which Russian roulette may end a path"))
            .param(intParam("seed", 1, 0, 1 << 30, "random sequence; the same seed gives the same image"))
            .param(boolParam("jitter", true, "integrate over each pixel's area (off: through pixel centres)"))
            .param(intParam("budget_ms", 1000, 0, 60000,
                            "stop dispatching in a frame after this long and go on in the next (0: no limit); keeps "
                            "one call far under the watchdog on a large or slow frame"));
        d.reads = kSceneGeometry | kSceneLights | kSceneCamera;
        d.timeDependent = true;  // accumulates every frame; resets itself on change
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        using namespace kiln;
        GLuint program = ctx.program({.stages = {"reference/path.comp"}});
        if (!program) return;
        const TextureRef& radiance = ctx.output("radiance");
        const TextureRef& direct = ctx.output("direct");
        const SceneView& scene = ctx.scene();

        const uint64_t key = accumulationKey(ctx, radiance, direct);
        if (key != key_) key_ = key, samples_ = 0, band_ = 0;
        const int maxSamples = ctx.getInt("max_samples");
        if (samples_ >= maxSamples) {
            ctx.nothingToDo("converged: " + std::to_string(samples_) + " paths per pixel");
            return;
        }
        const int batch = std::min(ctx.getInt("samples_per_frame"), maxSamples - samples_);

        glUseProgram(program);
        GLint first[kSceneGeometryCount], count[kSceneGeometryCount];
        for (int i = 0; i < kSceneGeometryCount; ++i) {
            first[i] = GLint(scene.firstInstance(SceneCategory(1u << i)));
            count[i] = GLint(scene.counts[i]);
        }
        glUniform1iv(glGetUniformLocation(program, "u_first"), kSceneGeometryCount, first);
        glUniform1iv(glGetUniformLocation(program, "u_count"), kSceneGeometryCount, count);
        glUniform1ui(glGetUniformLocation(program, "u_seed"), GLuint(ctx.getInt("seed")));
        glUniform1i(glGetUniformLocation(program, "u_maxBounces"), ctx.getInt("max_bounces"));
        glUniform1i(glGetUniformLocation(program, "u_rouletteStart"), ctx.getInt("roulette_start"));
        glUniform1i(glGetUniformLocation(program, "u_jitter"), ctx.getBool("jitter") ? 1 : 0);
        kiln::bindRayMeshes(scene, program);
        kiln::gl::bindImage(program, "u_radiance", radiance.id, 0, false, GL_READ_WRITE, GL_RGBA32F);
        kiln::gl::bindImage(program, "u_direct", direct.id, 0, false, GL_READ_WRITE, GL_RGBA32F);
        kiln::gl::bindImage(program, "u_rays", ctx.output("rays").id, 0, false, GL_READ_WRITE, GL_R32F);
        // A few paths per dispatch: llvmpipe silently ends a shader loop after 65 535
        // iterations (counted across the nesting), which dropped every path beyond
        // ~215 in one invocation of the analytic scene; 8 per dispatch stays far below.
        // A BVH walk is up to a few hundred iterations a ray, so with meshes one path.
        const int pathsPerDispatch = scene.rayMeshes.instanceCount > 0 ? 1 : 8;
        // The picture in bands of rows, so that a frame can stop within its budget and
        // the next go on where it stopped; a pixel's paths are the same whatever the
        // bands (its random numbers follow its position and path index).
        const int bands = (radiance.height + kBandRows - 1) / kBandRows;
        const int budgetMs = ctx.getInt("budget_ms");
        const auto start = std::chrono::steady_clock::now();
        const int target = samples_ + batch;
        while (samples_ < target) {
            if (band_ == 0) bandPaths_ = std::min(pathsPerDispatch, target - samples_);
            const int paths = bandPaths_;  // every band of one pass adds as many
            glUniform1i(glGetUniformLocation(program, "u_sampleBase"), samples_);
            glUniform1i(glGetUniformLocation(program, "u_samples"), paths);
            glUniform1i(glGetUniformLocation(program, "u_rowOffset"), band_ * kBandRows);
            const int rows = std::min(kBandRows, radiance.height - band_ * kBandRows);
            glDispatchCompute(GLuint((radiance.width + 7) / 8), GLuint((rows + 7) / 8), 1);
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            if (++band_ == bands) band_ = 0, samples_ += paths;
            if (budgetMs > 0 && samples_ < target) {
                glFinish();  // the time the dispatches took, not the time to queue them
                if (std::chrono::steady_clock::now() - start > std::chrono::milliseconds(budgetMs)) break;
            }
        }
    }

private:
    // Everything whose change makes the mean so far wrong.
    static uint64_t accumulationKey(kiln::PassContext& ctx, const kiln::TextureRef& a, const kiln::TextureRef& b) {
        using namespace kiln;
        const SceneView& s = ctx.scene();
        const int time = sceneCategoryIndex(kSceneTime);
        uint64_t h = fnv1a(s.counts, sizeof s.counts);
        for (int i = 0; i < kSceneCategoryCount; ++i)
            if (i != time) h = fnv1a(&s.versions[i], sizeof s.versions[i], h);
        const int values[] = {ctx.getInt("max_bounces"), ctx.getInt("roulette_start"), ctx.getInt("seed"),
                              ctx.getBool("jitter") ? 1 : 0, int(a.id), int(b.id), a.width, a.height};
        return fnv1a(values, sizeof values, h);
    }

    static constexpr int kBandRows = 64;
    uint64_t key_ = 0;
    int samples_ = 0;  // paths in every pixel of the bands before band_; one pass more after
    int band_ = 0;     // the next band to dispatch
    int bandPaths_ = 0;  // what the pass under way adds to each pixel
};

}  // namespace

KILN_PASS_MODULE(reference, Reference)
