// voxel_mip — mip chains of the voxel radiance, compute shaders in 4³
// workgroups, one dispatch per level.
//
// Outputs (both the input's res³, SizeRule::fromInput, with a full mip chain; colours
// premultiplied by opacity):
//   iso    level 0 = a copy of the input, level k = the mean of its 2×2×2 children
//          (colour and opacity). Always built: it is cheap (1/7 of the voxels) and it
//          is level 0 of the anisotropic lookups and the voxel_view's volume.
//   aniso  (mode = aniso) six directional chains, Crassin et al. 2011: the value seen
//          looking along direction D through a parent = the mean over the 4 child
//          pairs along D of the front-to-back composite
//              c = c_front + (1 − a_front)·c_back,  a = a_front + (1 − a_front)·a_back,
//          front = the child met first travelling along D. They are stored as OCTANTS
//          of one res³ atlas: atlas level k holds directional level k+1 (res/2^(k+1)
//          per side), direction i ∈ {+x,−x,+y,−y,+z,−z} in the octant
//          (i&1, (i>>1)&1, i>>2). A cone with direction d takes three of them, chosen
//          by sign arithmetic (x: (d.x<0, 0, 0), y: (d.y<0, 1, 0), z: (d.z<0, 0, 1)),
//          weighted by d² — three fetches from one sampler, no branch (see
//          docs/performance.md: six samplers behind a ?: cost more than the three
//          fetches on llvmpipe).
//          The sampler must clamp coordinates half a texel inside the octant
//          (shaders/cone_trace/voxels.glsl does).
//   fixed_cones  (mode = fixed_cones) the aniso chains blended per direction of the
//          fixed cone set (shaders/common/fixed_cones.glsl, 12 directions): tile t of
//          level k is what a cone along direction t reads at directional level k+1,
//          i.e. Σ d²·(the three chains facing d). Filtering is linear, so one lookup
//          here equals cone_trace's three; the blend costs 12 writes per voxel of
//          levels ≥ 1 (1/7 of the volume) once per voxel change instead of two more
//          fetches per cone step per pixel. aniso.comp blends each level as it builds it.
// Chains a mode does not build are cleared to zero once and left alone; binding one
// is a pipeline error (producedWhen), so no cone reads them.
//
// Bounces. voxelize's radiance holds direct light and emission, so the
// pixels' cones gather one bounce; in a closed, bright box the later ones are a large
// share (one bounce showed well under the reference's indirect light). With bounces = k > 1
// and voxelize's `albedo` and `normal` bound, the chains are built, then k − 1 times:
// every block of gather_block³ voxels that holds a surface traces the fixed cone set
// through them (shaders/voxel_mip/bounce.comp), level 0 becomes the input plus albedo ×
// that mean incoming radiance, and the chains are rebuilt from it. Deterministic and
// bounded: each bounce adds at most albedo × the last one, so the frame shows exactly
// k bounces and the path tracer with max_bounces = k + 1 is its ground truth
// (tests/gi/test_bounces.cpp, with the white furnace's 2 − 0.5^k).
//
// Feedback (`feedback`, the default pipeline's). Level 0 starts as the input plus what
// each surface voxel reflects of the light its block gathered last frame (the
// `feedback` internal), the k − 1 bounces follow as above, and one more gather is kept
// for the next frame. Frame n from a cold start shows n·k bounces; the frames converge
// to every bounce (the furnace: close to its 2), geometrically at about the albedo a frame,
// and the reflected light is a frame behind motion. After a change the pass asks the
// host for kFeedbackSettleFrames more frames (ctx.keepRunning), so a paused frame
// converges and then is skipped again. One gather and one chain build a frame (k = 1)
// instead of k − 1 and k: far cheaper than gathering three bounces in the frame. With
// `gather_list` (default) the kept gather runs only over the blocks that hold a surface,
// listed each frame for an indirect dispatch (bounce.comp's step 3; about a third of the
// 16³ blocks in the shipped box): the same light, for less.
//
// Facing (`facing`, needs `normal`). A voxel holds one radiance and one opacity; a
// cone leaving a surface met that surface's own voxels through the coarse levels, lit
// by them and shadowed by them. With `back`, directional level 1 is built from the
// base with each surface voxel that the direction meets from behind (its mean normal
// along the direction of travel) emptied: rays from outside a closed surface never
// meet its back (shaders/voxel_mip/aniso.comp). With the gather a diameter off its
// surfaces it cut much of the over-reflection of a third bounce against the path
// tracer's increment, and with 54° pixel cones brought the default closer to the
// reference (README, "The voxels' faces"). Most of what was left was the lookups past
// the box's open front (cone_trace/voxels.glsl insideBox), since fixed.
#include <kiln/pass.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace {

// The voxels' gather (bounce.comp) marches its cones as cone_trace does with its
// defaults: 60° cones on the octave schedule (one lookup per mip level, where the
// cone's diameter is that level's voxel, 0.87 diameters apart), pushed one voxel off the
// surface and half of each sample's diameter further (the default pipeline: a whole
// diameter, with `facing`).
constexpr float kGatherStartOffset = 1.0f;
constexpr float kGatherDiameterOffset = 0.5f;
// A gather's three jobs (bounce.comp's KILN_BOUNCE_STEP).
enum class BounceStep { GatherAndReflect = 0, GatherForNextFrame = 1, ReflectLastFrames = 2 };

// With feedback every frame adds `bounces` bounces to what the voxels converge to; the
// share of light still to come shrinks by about the surfaces' albedo a bounce (0.5 in
// the white furnace, under that in the open box), so 16 frames leave < 0.5^16 of it.
constexpr int kFeedbackSettleFrames = 16;

kiln::Defines gatherDefines(kiln::PassContext& ctx, int res, BounceStep step) {
    const float voxel = 2.0f / float(res), tanHalf = std::tan(float(M_PI) / 6.0f), maxDistance = 2.0f;
    std::string list;
    int steps = 0;
    for (int level = 0; (1 << level) <= res; ++level) {
        const float diameter = voxel * float(1 << level), t = diameter / (2.0f * tanHalf);
        if (t >= maxDistance) break;
        char step[128];
        std::snprintf(step, sizeof step, "%svec4(%.6f, %.6f, %d.0, %.6f)", steps++ ? ", " : "", t, diameter, level,
                      t / diameter);  // spacing to the next = t (the diameter doubles)
        list += step;
    }
    const std::string& mode = ctx.getEnum("mode");
    return {{"KILN_BOUNCE_STEP", std::to_string(int(step))},
            {"KILN_GATHER_BLOCK", std::to_string(ctx.getInt("gather_block"))},
            {"KILN_GATHER_LIST", ctx.getBool("gather_list") ? "1" : "0"},
            {"KILN_CONE_STEPS", std::to_string(steps)},
            {"KILN_CONE_SCHEDULE", list},
            {"KILN_HAS_ANISO", mode == "aniso" ? "1" : "0"},
            {"KILN_HAS_FIXED_CONES", mode == "fixed_cones" ? "1" : "0"}};
}

class VoxelMip final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        const auto cube = SizeRule::fromInput("radiance");
        d.input({.name = "radiance", .kind = TextureKind::Color3D, .doc = "voxelize.radiance"})
            .input({.name = "albedo", .kind = TextureKind::Color3D, .required = false,
                    .doc = "voxelize.albedo: what each voxel reflects (needed for bounces > 1)"})
            .input({.name = "normal", .kind = TextureKind::Color3D, .required = false,
                    .doc = "voxelize.normal: which way it faces (needed for bounces > 1)"})
            .output({.name = "iso", .kind = TextureKind::Color3D, .format = Format::RGBA16F, .size = cube,
                     .mips = kFullMipChain, .doc = "isotropic chain; level 0 = the input"})
            .output({.name = "aniso", .kind = TextureKind::Color3D, .format = Format::RGBA16F, .size = cube,
                     .mips = kFullMipChain,
                     .doc = "six directional chains as octants; atlas level k = directional level k+1",
                     .producedWhen = {"mode", {"aniso", "fixed_cones"}}})
            .output({.name = "fixed_cones", .kind = TextureKind::Color3D, .format = Format::RGBA16F,
                     .size = SizeRule::fromInput("radiance", 0.5f, 12), .mips = kFullMipChain,
                     .doc = "the aniso chains blended for each of the 12 fixed cone directions (tiles along x); "
                            "level k = directional level k+1",
                     .producedWhen = {"mode", {"fixed_cones"}}})
            .internal({.name = "bounced", .kind = TextureKind::Color3D, .format = Format::RGBA16F, .size = cube,
                       .doc = "bounces > 1: level 0 with one more bounce, before it replaces iso's"})
            .internal({.name = "feedback", .kind = TextureKind::Color3D, .format = Format::RGBA16F, .size = cube,
                       .doc = "feedback: the light each voxel's block gathered last frame (mean incoming radiance)"})
            .param(enumParam("mode", "aniso", {"iso", "aniso", "fixed_cones"},
                             "iso: the isotropic chain only; aniso: the six directional chains too; "
                             "fixed_cones: those blended per fixed cone direction as well"))
            .param(intParam("bounces", 1, 1, 8,
                            "diffuse bounces the frame shows: 1 = the voxels hold direct light and emission (the "
                            "pixels gather one bounce); each more is gathered in the voxels first"))
            .param(boolParam("feedback", false,
                             "the voxels start each frame from the last frame's bounced light and gather once more "
                             "for the next: every bounce once converged (`bounces` more a frame), a frame behind "
                             "motion; needs `albedo` and `normal`"))
            .param(enumParam("facing", "off", {"off", "back", "back_and_edge"},
                             "directional chains (needs `normal`): back: a surface voxel a cone meets from "
                             "behind is empty (every cone leaves its own surface that way); back_and_edge: "
                             "edge-on too (a cone along a wall passes it, and meets an oblique wall less)"))
            .param(intChoiceParam("gather_block", 2, {1, 2},
                                  "bounces > 1: voxels per side that gather once together (2: an eighth of the cones)"))
            .param(boolParam("gather_list", true,
                             "feedback: gather only at the blocks that hold a surface, listed each frame (off: "
                             "every block, the same light at more cost; kept to check that)"))
            .param(floatParam("gather_start_offset", kGatherStartOffset, 0.0, 4.0,
                              "bounces > 1: a voxel's cones start this many voxels off its surface"))
            .param(floatParam("gather_diameter_offset", kGatherDiameterOffset, 0.0, 2.0,
                              "bounces > 1: each sample pushed off the surface by this × its diameter"));
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint iso = ctx.program({.stages = {"voxel_mip/iso.comp"}});
        // aniso.comp: its first level from the base (with the facing rule), the rest each
        // from the one before.
        const std::string& facingMode = ctx.getEnum("facing");
        const char* facing = facingMode == "back" ? "1" : facingMode == "back_and_edge" ? "2" : "0";
        const char* blended = ctx.getEnum("mode") == "fixed_cones" ? "1" : "0";
        const AnisoPrograms aniso{
            ctx.program({.stages = {"voxel_mip/aniso.comp"},
                         .defines = {{"KILN_ANISO_FROM_BASE", "1"}, {"KILN_ANISO_FACING", facing},
                                     {"KILN_ANISO_FIXED_CONES", blended}}}),
            ctx.program({.stages = {"voxel_mip/aniso.comp"},
                         .defines = {{"KILN_ANISO_FROM_BASE", "0"}, {"KILN_ANISO_FIXED_CONES", blended}}})};
        if (!iso || !aniso.fromBase || !aniso.fromLevel) return;
        const kiln::TextureRef& in = ctx.input("radiance");
        const kiln::TextureRef& chain = ctx.output("iso");
        const int bounces = ctx.getInt("bounces");
        const bool feedback = ctx.getBool("feedback");
        const bool gathers = bounces > 1 || feedback;
        if (gathers && !(ctx.isBound("albedo") && ctx.isBound("normal")))
            return ctx.fail(std::string(feedback ? "feedback" : "bounces " + std::to_string(bounces)) +
                            " needs `albedo` and `normal` bound (voxelize.albedo, voxelize.normal): what each voxel "
                            "reflects, and which way");
        if (ctx.getEnum("facing") != "off" && !ctx.isBound("normal"))
            return ctx.fail("facing needs `normal` bound (voxelize.normal): which way each voxel's surface faces");
        // The grid (= the input's, SizeRule::fromInput) and its longest side, the cones' unit.
        const glm::ivec3 grid(chain.width, chain.height, chain.depth);
        const int res = std::max({grid.x, grid.y, grid.z});
        auto gatherProgram = [&](BounceStep step) {
            return ctx.program({.stages = {"voxel_mip/bounce.comp"}, .defines = gatherDefines(ctx, res, step)});
        };
        const GLuint bounce = bounces > 1 ? gatherProgram(BounceStep::GatherAndReflect) : 0;
        const GLuint keep = feedback ? gatherProgram(BounceStep::GatherForNextFrame) : 0;
        const bool listed = feedback && ctx.getBool("gather_list");
        const GLuint reflectKept = feedback ? gatherProgram(BounceStep::ReflectLastFrames) : 0;
        if ((bounces > 1 && !bounce) || (feedback && !(keep && reflectKept))) return;
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

        // Level 0: the input, or with feedback the input plus what its surfaces reflect
        // of the last frame's gather (nothing on the first frame after the texture was
        // made or feedback turned on).
        const kiln::TextureRef& kept = ctx.internal("feedback");
        if (feedback) {
            const glm::ivec3 keptGrid(kept.width, kept.height, kept.depth);
            if (keptId_ != kept.id || keptGrid_ != keptGrid) {  // a name can be reused for a new texture
                clearAllLevels(kept);
                keptId_ = kept.id;
                keptGrid_ = keptGrid;
            }
            if (listed) startGatherList(ctx);  // the reflection lists the blocks to gather at
            dispatchGather(ctx, reflectKept, chain.id, 0);
        } else {
            keptId_ = 0;  // turned back on later: starts from nothing
            glCopyImageSubData(in.id, GL_TEXTURE_3D, 0, 0, 0, 0, chain.id, GL_TEXTURE_3D, 0, 0, 0, 0, grid.x, grid.y, grid.z);
        }
        buildChains(ctx, iso, aniso);

        // Each further bounce: gather through the chains just built into `bounced`, make
        // it level 0, rebuild the chains from it.
        for (int b = 2; b <= bounces; ++b) {
            const kiln::TextureRef& bounced = ctx.internal("bounced");
            dispatchGather(ctx, bounce, bounced.id, chain.id);
            glCopyImageSubData(bounced.id, GL_TEXTURE_3D, 0, 0, 0, 0, chain.id, GL_TEXTURE_3D, 0, 0, 0, 0, grid.x, grid.y,
                               grid.z);
            buildChains(ctx, iso, aniso);
        }
        if (feedback) {
            dispatchGather(ctx, keep, kept.id, chain.id, listed);
            ctx.keepRunning(kFeedbackSettleFrames, "voxel bounces fed back");
        }
    }

private:
    static GLuint groups(int n) { return GLuint((n + 3) / 4); }
    static glm::ivec3 gridOf(const kiln::TextureRef& t) { return {t.width, t.height, t.depth}; }

    // gatherList_ emptied, for the reflection of the kept gather (bounce.comp step 2) to
    // list the blocks that hold a surface for the gather's indirect dispatch (step 1).
    void startGatherList(kiln::PassContext& ctx) {
        const glm::ivec3 blocks = gridOf(ctx.output("iso")) / ctx.getInt("gather_block");
        const GLsizeiptr bytes = 16 + 4 * GLsizeiptr(blocks.x) * blocks.y * blocks.z;
        if (!gatherList_ || gatherList_.size() < bytes)
            gatherList_ = kiln::gl::Buffer::create(bytes, nullptr, GL_DYNAMIC_STORAGE_BIT, "voxel_mip.gather_list");
        const GLuint empty[4] = {0, 1, 1, 0};  // no groups yet, 1 × 1; nothing listed
        glNamedBufferSubData(gatherList_.id(), 0, sizeof empty, empty);
    }

    // One bounce.comp dispatch over the voxels' blocks, writing `target`'s level 0;
    // `chainsRead` (iso) and the other chains are what its cones trace, if it gathers.
    // `listed`: over the blocks step 2 listed, an indirect dispatch.
    void dispatchGather(kiln::PassContext& ctx, GLuint program, GLuint target, GLuint chainsRead, bool listed = false) {
        const glm::ivec3 grid = gridOf(ctx.output("iso"));
        glUseProgram(program);
        glUniform1f(glGetUniformLocation(program, "u_voxelRes"), float(std::max({grid.x, grid.y, grid.z})));
        glUniform3f(glGetUniformLocation(program, "u_voxelDims"), float(grid.x), float(grid.y), float(grid.z));
        glUniform1f(glGetUniformLocation(program, "u_startOffset"), ctx.getFloat("gather_start_offset"));
        glUniform1f(glGetUniformLocation(program, "u_diameterOffset"), ctx.getFloat("gather_diameter_offset"));
        kiln::gl::bindTexture(program, "u_emitted", ctx.input("radiance").id);
        kiln::gl::bindTexture(program, "u_albedo", ctx.input("albedo").id);
        kiln::gl::bindTexture(program, "u_normal", ctx.input("normal").id);
        kiln::gl::bindTexture(program, "u_gathered", ctx.internal("feedback").id);
        if (chainsRead) {
            kiln::gl::bindTexture(program, "u_voxels", chainsRead);
            kiln::gl::bindTexture(program, "u_aniso", ctx.output("aniso").id);
            kiln::gl::bindTexture(program, "u_fixedCones", ctx.output("fixed_cones").id);
        }
        kiln::gl::bindImage(program, "u_bounced", target, 0, true, GL_WRITE_ONLY, GL_RGBA16F);
        kiln::gl::bindImage(program, "u_forgotten", ctx.internal("feedback").id, 0, true, GL_WRITE_ONLY, GL_RGBA16F);
        if (gatherList_) kiln::gl::bindStorageBuffer(program, "GatherList", gatherList_.id());
        if (listed) {
            glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, gatherList_.id());
            glDispatchComputeIndirect(0);
            glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
        } else {
            const glm::ivec3 blocks = grid / ctx.getInt("gather_block");
            glDispatchCompute(groups(blocks.x), groups(blocks.y), groups(blocks.z));
        }
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                        GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    }

    // Every chain the mode builds, from iso's level 0.
    struct AnisoPrograms {
        GLuint fromBase = 0, fromLevel = 0;
    };
    void buildChains(kiln::PassContext& ctx, GLuint iso, const AnisoPrograms& anisoPrograms) {
        const kiln::TextureRef& chain = ctx.output("iso");
        const kiln::TextureRef& atlas = ctx.output("aniso");
        const kiln::TextureRef& fixed = ctx.output("fixed_cones");
        const std::string& mode = ctx.getEnum("mode");
        const glm::ivec3 grid = gridOf(chain);
        const bool facing = ctx.getEnum("facing") != "off";
        glUseProgram(iso);
        for (int level = 1; level < chain.levels; ++level) {
            const glm::ivec3 n = glm::max(grid >> level, glm::ivec3(1));
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            kiln::gl::bindImage(iso, "u_src", chain.id, level - 1, true, GL_READ_ONLY, GL_RGBA16F);
            kiln::gl::bindImage(iso, "u_dst", chain.id, level, true, GL_WRITE_ONLY, GL_RGBA16F);
            glDispatchCompute(groups(n.x), groups(n.y), groups(n.z));
        }

        const bool blended = mode == "fixed_cones";
        if (mode != "iso") {
            // Directional level L (1 … log2 of the shortest side) lives in atlas level L−1,
            // octant sides grid>>L; with fixed_cones, blended into the fixed chains' level
            // L−1 as it is built. Past the shortest side's last level an octant would be
            // under one voxel across: the cones read the top level there (voxels.glsl).
            const int shortest = std::min({grid.x, grid.y, grid.z});
            for (int L = 1; (shortest >> L) >= 1; ++L) {
                const glm::ivec3 n = grid >> L;
                const GLuint aniso = L == 1 ? anisoPrograms.fromBase : anisoPrograms.fromLevel;
                glUseProgram(aniso);
                glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
                if (L == 1)
                    kiln::gl::bindImage(aniso, "u_src", chain.id, 0, true, GL_READ_ONLY, GL_RGBA16F);
                else
                    kiln::gl::bindImage(aniso, "u_src", atlas.id, L - 2, true, GL_READ_ONLY, GL_RGBA16F);
                kiln::gl::bindImage(aniso, "u_dst", atlas.id, L - 1, true, GL_WRITE_ONLY, GL_RGBA16F);
                if (blended) kiln::gl::bindImage(aniso, "u_fixed", fixed.id, L - 1, true, GL_WRITE_ONLY, GL_RGBA16F);
                if (facing && L == 1) kiln::gl::bindTexture(aniso, "u_normal", ctx.input("normal").id);
                glUniform3i(glGetUniformLocation(aniso, "u_size"), n.x, n.y, n.z);
                glDispatchCompute(groups(n.x), groups(n.y), groups(n.z));
            }
            atlasCleared_ = false;
        } else if (!atlasCleared_) {
            clearAllLevels(atlas);
            atlasCleared_ = true;
        }
        if (blended) {
            fixedCleared_ = false;
        } else if (!fixedCleared_) {
            clearAllLevels(fixed);
            fixedCleared_ = true;
        }
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    }

    static void clearAllLevels(const kiln::TextureRef& t) {
        for (int l = 0; l < t.levels; ++l) glClearTexImage(t.id, l, GL_RGBA, GL_FLOAT, nullptr);
    }

    GLuint keptId_ = 0;          // the feedback texture cleared last: another (or 0) means start over
    glm::ivec3 keptGrid_{0};
    bool atlasCleared_ = false;  // cache flags only
    bool fixedCleared_ = false;
    kiln::gl::Buffer gatherList_;  // feedback with gather_list: the dispatch size, the count, the blocks
};

}  // namespace

KILN_PASS_MODULE(voxel_mip, VoxelMip)
