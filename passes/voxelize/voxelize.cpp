// voxelize — the scene's outgoing radiance in a voxel grid over the scene's bounds
// (GpuFrame::voxelVolume; `resolution` cells along the longest side, the others in
// proportion, kiln::voxelGridShift):
// direct light from the lamp (hard shadow from `shadow_map`, no PCF; the
// same lampLight() as composite) plus emission, from the Cornell box, the lamp dome,
// the tumblers (low-poly LOD), the fireballs and the particles (marbles on request).
// The lamp dome is voxelized as an occluder, its emission scaled by `lamp_emission`
// (default 0): the lamp's light reaches every surface through composite's direct term
// already; with its emission in the voxels too, the first bounce would add the lamp a
// second time (measured: walls far too bright, colours washed out).
//
// How it works
//   1. Draw the meshes into an attachment-less framebuffer of res×res pixels. The
//      geometry shader projects each triangle on the axis its normal is most aligned
//      with (so every triangle covers as many pixels as it can) and enlarges it by
//      half a pixel diagonal (conservative rasterisation, Hasselgren et al., GPU Gems
//      2 ch. 42): triangles thinner than a voxel (a wall seen edge-on by no axis, a
//      particle smaller than a voxel) still produce fragments; the fragment shader
//      discards what falls outside the triangle's own bounding box + half a pixel.
//   2. Each fragment covers one voxel column along the projection axis; it writes
//      every voxel its depth spans over the pixel (depth ± ½(|∂z/∂x|+|∂z/∂y|)), so a
//      tilted surface leaves no 6-connected gap (light can't leak through it) and an
//      axis-aligned wall is exactly one voxel thick.
//   3. Combining fragments that land in one voxel: an exact AVERAGE, order-free. Four
//      R32UI grids (channels of the internal `sums`) receive imageAtomicAdd of
//      the fragment's radiance in 1/512 fixed point (clamped to 2048 per channel, so
//      over 4000 fragments fit a voxel before overflow) and of 1. No compare-and-swap
//      loop (the RGBA8 running-average trick serialises colliding fragments and
//      quantises radiance to 8 bits; imageStore of RGBA16F would keep an arbitrary
//      last fragment).
//   Particles (thousands of tiny emitters) skip steps 1–2 by default, fireballs
//      (spheres of about a voxel) on request (fireball_mode splat): a compute pass
//      (voxelize/splat.comp) adds each one, as one fragment, to the voxels its surface
//      passes through, a fireball's lit by the lamp as a fragment there would be.
//      Rasterized, each particle cost 8 geometry-shader triangles: thousands of
//      particles made voxelize far dearer (particle_mode "mesh").
//      The fireballs stay meshes by default: their rasterized triangles give a voxel
//      several fragments where the splat gives one, and the reference slightly prefers
//      that weight.
//   The tumblers on request (tumbler_mode splat): a compute pass (voxelize/tumblers.comp)
//      adds one fragment to each voxel their exact round cone's surface passes through,
//      lit at the surface point nearest the voxel's centre; rasterizing their low-poly
//      meshes through the geometry shader cost a large share of voxelize, the splat
//      much less. Not the default: against the reference the floor next to
//      the tumblers is worse, though every region's mean light is closer (the floor's
//      indirect light among them).
//   The particles' cover on request (fire_cover on), first: a compute pass
//      (voxelize/fire_cover.comp) shares each particle's cross-section among the voxels
//      it overlaps, resolved into `fire` (the optical depth across each voxel, with mips);
//      then `lamp_transmittance`, the fraction of the lamp seen past it and the fireballs
//      on a coarser grid (transmittance_resolution; voxelize/fire_transmittance.comp,
//      common/fire.glsl): the fire rising round the dome hides part of the lamp. The
//      resolve takes the lamp's part of each voxel's light (summed apart from what it
//      emits) through it; cone_trace takes the pixels' for composite.
//   4. A compute pass (4³ groups) resolves sum/count into `radiance`: rgb = the mean
//      outgoing radiance, a = occupancy (1 where any fragment landed, else 0). The
//      colour is premultiplied by the occupancy (empty voxels are 0,0,0,0), which is
//      what the mip passes average and what the cone tracer composites. Surfaces also
//      add their albedo and normal (six more sums), resolved into `albedo` and
//      `normal`: what voxel_mip needs to bounce the light the voxels hold.
//
// Rebuilt whenever it runs, from the static surfaces' voxels up (keep_static): the lamp
// dome and the walls are rasterized once into `static_sums` (and again when the lamp,
// the box, the resolution, the programs or the parameters they depend on change), which
// is copied in each frame in place of a clear. The dome is lit there for good (it is the
// emitter; nothing that moves reaches the space between it and the shadow map's eye);
// the walls' light changes with every moving shadow, so their fragments are recorded
// (point, normal, albedo, voxels, and the lamp's unshadowed irradiance, which changes
// only with the lamp) and voxelize/static_light.comp takes each one's shadow test again
// each frame and adds its light, as the fragment shader would, to the frame's sums.
// Keeping the dome, then the walls, each makes a moving frame cheaper (lighting the
// walls' fragments again is cheaper still with their irradiance kept); the voxels are
// the same, exactly (keep_static off rasterizes everything every frame; tests/gi/test_gi.cpp
// compares the two). The host skips the pass when neither the scene
// (static geometry, bodies, particles, light) nor the shadow map changed.
#include <kiln/pass.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

namespace {

class Voxelize final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        const auto cube = SizeRule::fromParam("resolution");
        d.input({.name = "shadow_map", .kind = TextureKind::Depth2D, .required = false,
                 .doc = "the lamp's depth map (shadow.depth); unbound: everything lit"})
            .input({.name = "light_shadows", .kind = TextureKind::Depth2D, .required = false,
                    .fallback = Fallback::FarDepth,
                    .doc = "the punctual lights' shadow atlas (lights.shadow_atlas); read only when the scene has them"})
            .output({.name = "radiance", .kind = TextureKind::Color3D, .format = Format::RGBA16F, .size = cube,
                     .doc = "rgb = mean outgoing radiance × occupancy, a = occupancy (0/1)"})
            .output({.name = "albedo", .kind = TextureKind::Color3D, .format = Format::RGBA8, .size = cube,
                     .doc = "rgb = the surfaces' mean albedo (particles count as 0), a = occupancy"})
            .output({.name = "normal", .kind = TextureKind::Color3D, .format = Format::RGBA16F, .size = cube,
                     .doc = "xyz = the surfaces' mean unit normal (shorter where they disagree), a = occupancy"})
            .output({.name = "fire", .kind = TextureKind::Color3D, .format = Format::R16F, .size = cube,
                     .mips = kFullMipChain,
                     .doc = "fire_cover on: the fire particles' optical depth across each voxel (their "
                            "cross-sections per voxel face); mips: the mean",
                     .producedWhen = {"fire_cover", {"on"}}})
            .output({.name = "lamp_transmittance", .kind = TextureKind::Color3D, .format = Format::R16F,
                     .size = SizeRule::fromParam("transmittance_resolution"),
                     .doc = "fire_cover on: the fraction of the lamp each node of a grid of "
                            "transmittance_resolution³ sees past the fireballs and particles "
                            "(shaders/common/fire.glsl)",
                     .producedWhen = {"fire_cover", {"on"}}});
        d.internal({.name = "sums", .kind = TextureKind::Color3D, .format = Format::R32UI,
                    .size = SizeRule::fromParam("resolution", 1.0f, kSumChannels),
                    .doc = "the fixed-point accumulators (shaders/voxelize/sums.glsl): radiance rgb, fragment "
                           "count, albedo rgb, normal xyz, the particles' cover and (fire_cover on) the emitted part of the "
                           "radiance apart, fourteen grids side by side along x"});
        d.internal({.name = "static_sums", .kind = TextureKind::Color3D, .format = Format::R32UI,
                    .size = SizeRule::fromParam("resolution", 1.0f, kSumChannels),
                    .doc = "the lamp dome's sums and the walls' without their lamp light, built when the "
                           "lamp or the box changes: each frame's sums start from them"});
        d.internal({.name = "lamp_field", .format = Format::RG16F, .size = SizeRule::fixed(kLampFieldSide, kLampFieldSide),
                    .doc = "lamp_model field: the lamp's vector irradiance over (distance from its axis, height)"});
        d.param(intChoiceParam("resolution", 64, {32, 64, 128}, "voxels along the longest side of the scene's bounds (the other sides in proportion, as powers of two)"))
            .param(boolParam("conservative", true, "enlarge triangles by half a voxel (no holes from thin triangles)"))
            .param(boolParam("keep_static", true,
                             "rasterize the walls and the lamp dome once (again when they or the lamp change) "
                             "and each frame only light the walls' kept fragments again; off: rasterize "
                             "every surface every frame (the same voxels, for comparison)"))
            .param(boolParam("marbles", false, "voxelize the marbles too (the course design leaves them out)"))
            .param(boolParam("particles", true, "voxelize the emissive particles"))
            .param(enumParam("particle_mode", "splat", {"splat", "mesh"},
                             "splat: a compute pass adds each particle to the voxels it overlaps; mesh: rasterize "
                             "its octahedron like every other mesh"))
            .param(floatParam("fireball_emission", 1.0f, 0.0, 1.0,
                              "the fireballs' emission in the voxels: 1, they light surfaces "
                              "through the cones; 0 when composite lights surfaces with them directly "
                              "(composite.fireball_light analytic) and the voxels keep only what they light"))
            .param(boolParam("fireball_flux", false,
                             "scale each fireball's emission by pi r^2 / (2r + h)^2 (h: the voxel side), so its "
                             "voxelized blob carries the sphere's flux"))
            .param(enumParam("fireball_mode", "mesh", {"mesh", "splat"},
                             "mesh: rasterize its sphere like every other mesh; splat: a compute pass adds each "
                             "fireball, as one fragment, to the voxels its surface passes through (as "
                             "accurate, and many fireballs cost the frame less than their meshes do)"))
            .param(enumParam("tumbler_mode", "mesh", {"mesh", "splat"},
                             "mesh: rasterize the low-poly mesh like every other mesh; splat: a compute pass adds "
                             "one fragment to each voxel the exact shape's surface passes through "
                             "(voxelize/tumblers.comp): a cheaper voxelize, but further from the "
                             "reference (the floor by the tumblers)"))
            .param(floatParam("lamp_emission", 0.0f, 0.0, 1.0,
                              "scale of the lamp dome's own emission in the voxels (its light already arrives "
                              "through composite's direct term: 1 counts it twice)"))
            .param(enumParam("lamp_model", "contour", {"contour", "points", "field"},
                             "the lamp's irradiance on voxelized surfaces (shaders/common/light.glsl): its "
                             "silhouette's contour integral (16 vertices), 32 quadrature points over the cap, or "
                             "one lookup in its vector irradiance on a 256² axisymmetric grid (the `lamp_field` "
                             "internal, built when the lamp changes; shaders/common/lamp_field.comp)"))
            .param(floatParam("shadow_bias", 0.002f, 0.0, 0.05, "depth bias of the (hard) shadow test"))
            .param(enumParam("fire_cover", "off", {"off", "on"},
                             "on: the lamp's light reaches the voxels through the fire (the fireballs and "
                             "particles), and `lamp_transmittance` holds the fraction of it seen past the fire "
                             "for cone_trace (composite's lamp_through_fire)"))
            .param(intChoiceParam("transmittance_resolution", 32, {8, 16, 32, 64},
                                  "fire_cover on: nodes per side of `lamp_transmittance`, the grid the fraction of "
                                  "the lamp seen past the fire is computed on (each node marches the particles' "
                                  "cover and tests the fireballs against the cap: a finer grid costs "
                                  "more). The lamp is large, so the fraction changes slowly away from "
                                  "the fire"));
        d.reads = kSceneStatic | kSceneMeshes | kSceneBodies | kSceneParticles | kSceneLights;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        // 16 silhouette vertices (within 1 % of the exact irradiance; tests/gi/test_lamp.cpp)
        // or the old 32 quadrature points.
        const bool contour = ctx.getEnum("lamp_model") == "contour", field = ctx.getEnum("lamp_model") == "field";
        const bool fireCover = ctx.getEnum("fire_cover") == "on";
        const kiln::Defines lamp = {{"KILN_LAMP_CONTOUR", contour ? "1" : "0"},
                                    {"KILN_LAMP_SAMPLES", contour || field ? "16" : "32"},
                                    {"KILN_LAMP_FIELD", field ? "1" : "0"},
                                    {"KILN_FIRE_THROUGH", fireCover ? "1" : "0"},
                                    {"KILN_PUNCTUAL", ctx.scene().frame.punctualCount.x > 0 ? "1" : "0"}};
        const std::vector<std::string> rasterStages = {"voxelize/voxelize.vert", "voxelize/voxelize.geom",
                                                       "voxelize/voxelize.frag"};
        GLuint raster = ctx.program({.stages = rasterStages, .defines = lamp});
        const bool keepStatic = ctx.getBool("keep_static");
        kiln::Defines recordDefines = lamp;
        recordDefines.emplace_back("KILN_RECORD_STATIC", "1");
        GLuint recorder = keepStatic ? ctx.program({.stages = rasterStages, .defines = recordDefines}) : 0;
        GLuint staticLighter = keepStatic ? ctx.program({.stages = {"voxelize/static_light.comp"}, .defines = lamp}) : 0;
        GLuint resolve = ctx.program({.stages = {"voxelize/resolve.comp"}, .defines = lamp});
        GLuint coverer = fireCover ? ctx.program({.stages = {"voxelize/fire_cover.comp"}}) : 0;
        GLuint fireResolve = fireCover ? ctx.program({.stages = {"voxelize/fire_resolve.comp"}}) : 0;
        GLuint fireMip = fireCover ? ctx.program({.stages = {"voxelize/fire_mip.comp"}}) : 0;
        GLuint fireLight = fireCover ? ctx.program({.stages = {"voxelize/fire_transmittance.comp"}}) : 0;
        const bool particles = ctx.getBool("particles");
        const bool splatParticles = particles && ctx.getEnum("particle_mode") == "splat";
        const bool splatFireballs = ctx.getEnum("fireball_mode") == "splat";
        // splat.comp's two variants: the fireballs as lit surfaces, the particles as emitters.
        kiln::Defines litSpheres = lamp, emitters = lamp;
        litSpheres.push_back({"KILN_SPLAT_LIT", "1"});
        litSpheres.push_back({"KILN_SPLAT_GROUP", std::to_string(kFireballGroup)});
        emitters.push_back({"KILN_SPLAT_LIT", "0"});
        emitters.push_back({"KILN_SPLAT_GROUP", std::to_string(kParticleGroup)});
        const std::vector<std::string> splatStage = {"voxelize/splat.comp"};
        GLuint fireballSplatter = splatFireballs ? ctx.program({.stages = splatStage, .defines = litSpheres}) : 0;
        GLuint particleSplatter = splatParticles ? ctx.program({.stages = splatStage, .defines = emitters}) : 0;
        const bool splatTumblers = ctx.getEnum("tumbler_mode") == "splat";
        GLuint tumblerSplatter = splatTumblers ? ctx.program({.stages = {"voxelize/tumblers.comp"}, .defines = lamp}) : 0;
        if (!raster || !resolve || (keepStatic && (!recorder || !staticLighter)) ||
            (splatFireballs && !fireballSplatter) || (splatParticles && !particleSplatter) ||
            (splatTumblers && !tumblerSplatter) || (fireCover && (!coverer || !fireResolve || !fireMip || !fireLight)))
            return;
        if (field && !buildLampField(ctx)) return;
        const kiln::TextureRef& out = ctx.output("radiance");
        const glm::ivec3 res(out.width, out.height, out.depth);  // the grid: per axis (kiln::voxelGridShift)

        // The sums start from the static ones (integer sums: the order of adding is free),
        // then the walls' lamp light.
        const kiln::TextureRef& sums = ctx.internal("sums");
        if (keepStatic) {
            const kiln::TextureRef& staticSums = ctx.internal("static_sums");
            if (!voxelizeStatic(ctx, raster, recorder, res, staticSums)) return;
            glCopyImageSubData(staticSums.id, GL_TEXTURE_3D, 0, 0, 0, 0, sums.id, GL_TEXTURE_3D, 0, 0, 0, 0,
                               sums.width, sums.height, sums.depth);
            lightStatic(ctx, staticLighter, res);
        } else {
            glClearTexImage(sums.id, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
            builtStatic_ = {};
        }

        // The particles' cover and the transmittance grid from it: the resolve reads the grid.
        if (fireCover) coverFire(ctx, coverer, fireResolve, fireMip, fireLight, res);
        rasterize(ctx, raster, res, !keepStatic, particles && !splatParticles, !splatFireballs, !splatTumblers);
        if (fireballSplatter) splat(ctx, fireballSplatter, kFireballGroup, res, kiln::kSceneGlowingSpheres);
        if (particleSplatter) splat(ctx, particleSplatter, kParticleGroup, res, kiln::kSceneParticles);
        if (tumblerSplatter) splatTumblerShapes(ctx, tumblerSplatter, res);
        resolveSums(ctx, resolve, out, res);
    }

private:
    // keep_static: the lamp dome (lit: it is the emitter, nothing comes between it and
    // the shadow map's eye) and the walls without their lamp light into `static_sums`,
    // the walls' fragments recorded for lightStatic(); when what they depend on changed.
    // False when the pass failed.
    bool voxelizeStatic(kiln::PassContext& ctx, GLuint raster, GLuint recorder, glm::ivec3 res,
                        const kiln::TextureRef& staticSums) {
        const kiln::SceneView& scene = ctx.scene();
        // The debug view edits a parameter on the same object: the two the voxels depend
        // on are in the key (lamp_model and fire_cover change the programs).
        const StaticKey key{scene.version(kiln::kSceneLightSurface), scene.version(kiln::kSceneLights),
                            scene.version(kiln::kScenePlanes), scene.version(kiln::kSceneMeshes), scene.frame.ringsLight, scene.frame.ringsDark,
                            scene.frame.voxelVolume, scene.frame.voxelExtent, staticSums.id, raster, recorder, res,
                            ctx.getFloat("lamp_emission"), ctx.getBool("conservative")};
        if (key == builtStatic_) return true;
        // Room for every wall fragment: a wall covers at most (res + 2)² pixels of its
        // axis (the conservative half voxel), its triangles' shared edges a few more. A
        // shortfall is counted (u_recorded goes on): then it grows and records again.
        const int side = std::max({res.x, res.y, res.z});
        GLsizeiptr needed = std::max<GLsizeiptr>(GLsizeiptr(8) * (side + 2) * (side + 2), staticCapacity_);
        for (int attempt = 0; attempt < 2; ++attempt) {
            if (!staticFragments_ || needed > staticCapacity_) {
                staticCapacity_ = needed;
                staticFragments_ = kiln::gl::Buffer::create(kStaticHeaderBytes + staticCapacity_ * kStaticFragmentBytes,
                                                            nullptr, GL_DYNAMIC_STORAGE_BIT, "voxelize.static_fragments");
            }
            const GLuint header[4] = {0u, GLuint(staticCapacity_), 0u, 0u};
            glNamedBufferSubData(staticFragments_.id(), 0, sizeof header, header);
            glClearTexImage(staticSums.id, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
            beginRaster(ctx, raster, res, staticSums.id);
            drawDome(ctx, raster);
            beginRaster(ctx, recorder, res, staticSums.id);
            glUniform1f(glGetUniformLocation(recorder, "u_emissionScale"), 1.0f);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kStaticBinding, staticFragments_.id());
            drawSided(ctx, recorder, kiln::kScenePlanes | kiln::kSceneMeshes);
            glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                            GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
            GLuint recorded = 0;  // a read back, once a build
            glGetNamedBufferSubData(staticFragments_.id(), 0, sizeof recorded, &recorded);
            staticRecorded_ = recorded;
            if (GLsizeiptr(recorded) <= staticCapacity_) {
                builtStatic_ = key;
                return true;
            }
            needed = GLsizeiptr(recorded) + GLsizeiptr(recorded) / 4;
        }
        ctx.fail("the walls' fragments outgrew their buffer twice");
        return false;
    }

    // keep_static: the walls' recorded fragments lit by this frame's lamp and shadow map,
    // added to the sums (voxelize/static_light.comp).
    void lightStatic(kiln::PassContext& ctx, GLuint program, glm::ivec3 res) {
        if (staticRecorded_ == 0) return;
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        useSurfaceProgram(ctx, program, res);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kStaticBinding, staticFragments_.id());
        glDispatchCompute(GLuint((staticRecorded_ + 63) / 64), 1, 1);
    }

    // The raster state for adding meshes to sums `target`: the program in use with its
    // inputs bound, an attachment-less framebuffer of the voxels' size.
    void beginRaster(kiln::PassContext& ctx, GLuint raster, glm::ivec3 res, GLuint target) {
        // One viewport an axis (voxelize.geom), whole llvmpipe tiles apart, so that its
        // threads share the fragments (on one 32² viewport one thread shaded them all).
        // Along x the grid's y × z columns, along y its z × x, along z its x × y.
        const int side = std::max({res.x, res.y, res.z});
        const int axisStep = (side + kRasterTile - 1) / kRasterTile * kRasterTile;
        if (!fbo_) fbo_ = kiln::gl::createFramebuffer();
        if (fboSize_ != side) {
            glNamedFramebufferParameteri(fbo_.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, 3 * axisStep);
            glNamedFramebufferParameteri(fbo_.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, side);
            fboSize_ = side;
        }
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
        const glm::ivec2 viewport[3] = {{res.y, res.z}, {res.z, res.x}, {res.x, res.y}};
        for (GLuint axis = 0; axis < 3; ++axis)
            glViewportIndexedf(axis, float(axis) * axisStep, 0.0f, float(viewport[axis].x), float(viewport[axis].y));
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_CULL_FACE);
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        useSurfaceProgram(ctx, raster, res);
        kiln::gl::bindImage(raster, "u_sums", target, 0, true, GL_READ_WRITE, GL_R32UI);
        glUniform1f(glGetUniformLocation(raster, "u_conservative"), ctx.getBool("conservative") ? 1.0f : 0.0f);
        glUniform1i(glGetUniformLocation(raster, "u_axisViewportStep"), axisStep);
    }

    // `categories` into the sums `program` is set up for, the double-sided meshes apart
    // (voxelize.frag lights them on the side their light falls on).
    static void drawSided(kiln::PassContext& ctx, GLuint program, uint32_t categories) {
        const GLint twoSided = glGetUniformLocation(program, "u_twoSided");
        glUniform1i(twoSided, 0);
        ctx.drawScene({.categories = categories, .lod = kiln::Lod::Low, .sides = kiln::Sides::OneSided});
        if (!(categories & kiln::kSceneMeshes)) return;
        glUniform1i(twoSided, 1);
        ctx.drawScene({.categories = kiln::kSceneMeshes, .lod = kiln::Lod::Low, .sides = kiln::Sides::TwoSided});
        glUniform1i(twoSided, 0);
    }

    // The lamp dome into the sums `raster` is set up for (beginRaster): at lamp_emission,
    // unshadowed (it is the emitter; nothing comes between it and the shadow map's eye).
    static void drawDome(kiln::PassContext& ctx, GLuint raster) {
        glUniform1f(glGetUniformLocation(raster, "u_emissionScale"), ctx.getFloat("lamp_emission"));
        glUniform1i(glGetUniformLocation(raster, "u_unshadowed"), 1);
        ctx.drawScene({.categories = kiln::kSceneLightSurface, .lod = kiln::Lod::Low});
    }

    // 1–3: the box and the lamp (unless kept), the tumblers and whatever is not splatted,
    // rasterised into the sums (no attachments: the fragment shader only does atomics).
    void rasterize(kiln::PassContext& ctx, GLuint raster, glm::ivec3 res, bool rasterStatic, bool rasterParticles,
                   bool rasterFireballs, bool rasterTumblers) {
        beginRaster(ctx, raster, res, ctx.internal("sums").id);
        if (rasterStatic) drawDome(ctx, raster);
        const GLint emissionScale = glGetUniformLocation(raster, "u_emissionScale");
        glUniform1i(glGetUniformLocation(raster, "u_unshadowed"), 0);
        uint32_t cats = (rasterStatic ? kiln::kScenePlanes | kiln::kSceneMeshes : 0u) | (rasterTumblers ? kiln::kSceneRoundCones : 0u);
        if (rasterParticles) cats |= kiln::kSceneParticles;
        if (ctx.getBool("marbles")) cats |= kiln::kSceneSpheres;
        glUniform1f(emissionScale, 1.0f);
        drawSided(ctx, raster, cats);
        if (rasterFireballs) {
            glUniform1f(emissionScale, ctx.getFloat("fireball_emission"));
            glUniform1i(glGetUniformLocation(raster, "u_sphereFlux"), ctx.getBool("fireball_flux") ? 1 : 0);
            ctx.drawScene({.categories = kiln::kSceneGlowingSpheres, .lod = kiln::Lod::Low});
            glUniform1i(glGetUniformLocation(raster, "u_sphereFlux"), 0);
        }
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }

    // A program that lights surfaces (voxelize/surface.glsl) and adds them to the sums:
    // in use, with its shadow map, lamp field, sums and their uniforms bound.
    static void useSurfaceProgram(kiln::PassContext& ctx, GLuint program, glm::ivec3 res) {
        glUseProgram(program);
        kiln::gl::bindTexture(program, "u_shadowMap", ctx.input("shadow_map").id);
        kiln::gl::bindTexture(program, "u_lampField", ctx.internal("lamp_field").id);  // field only
        kiln::gl::bindTexture(program, "u_lightShadows", ctx.input("light_shadows").id);  // punctual lights only
        bindSums(ctx, program, GL_READ_WRITE);
        glUniform1i(glGetUniformLocation(program, "u_res"), std::max({res.x, res.y, res.z}));
        glUniform3i(glGetUniformLocation(program, "u_grid"), res.x, res.y, res.z);
        glUniform1f(glGetUniformLocation(program, "u_shadowBias"), ctx.getFloat("shadow_bias"));
    }

    // The fireballs or the particles, splatted by `splatter` (splat.comp: lit spheres or
    // emitters). One program with a branch between the two ran the fireballs' lighting for
    // every particle (llvmpipe runs an `if` for every lane), dearer than the two programs
    // apart. `groupSize`: the program's KILN_SPLAT_GROUP.
    static void splat(kiln::PassContext& ctx, GLuint splatter, uint32_t groupSize, glm::ivec3 res,
                      kiln::SceneCategory spheres) {
        const kiln::SceneView& scene = ctx.scene();
        const uint32_t count = scene.count(spheres);
        if (count == 0) return;
        useSurfaceProgram(ctx, splatter, res);
        glUniform1ui(glGetUniformLocation(splatter, "u_first"), scene.firstInstance(spheres));
        glUniform1ui(glGetUniformLocation(splatter, "u_sphereCount"), count);
        glUniform1f(glGetUniformLocation(splatter, "u_fireballEmission"), ctx.getFloat("fireball_emission"));
        glUniform1i(glGetUniformLocation(splatter, "u_sphereFlux"), ctx.getBool("fireball_flux") ? 1 : 0);
        glDispatchCompute((count + groupSize - 1) / groupSize, 1, 1);
    }

    // fire_cover: the particles' cross-sections into the sums (common/fire.glsl takes the
    // fireballs exactly), resolved into `fire` and its mips; then from them and the
    // fireballs `lamp_transmittance`, ready for the resolve's and cone_trace's lookups.
    static void coverFire(kiln::PassContext& ctx, GLuint coverer, GLuint resolver, GLuint mipper, GLuint lighter,
                          glm::ivec3 res) {
        const kiln::SceneView& scene = ctx.scene();
        const uint32_t count = scene.count(kiln::kSceneParticles);
        if (count > 0) {
            glUseProgram(coverer);
            bindSums(ctx, coverer, GL_READ_WRITE);
            glUniform1ui(glGetUniformLocation(coverer, "u_first"), scene.firstInstance(kiln::kSceneParticles));
            glUniform1ui(glGetUniformLocation(coverer, "u_sphereCount"), count);
            glUniform3i(glGetUniformLocation(coverer, "u_grid"), res.x, res.y, res.z);
            glDispatchCompute((count + 63) / 64, 1, 1);
        }
        const kiln::TextureRef& fire = ctx.output("fire");
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        glUseProgram(resolver);
        bindSums(ctx, resolver, GL_READ_ONLY);
        kiln::gl::bindImage(resolver, "u_fire", fire.id, 0, true, GL_WRITE_ONLY, GL_R16F);
        glDispatchCompute(groups(res.x), groups(res.y), groups(res.z));
        mipFire(ctx, mipper);
        // The lamp's transmittance on its grid, through the cover and the fireballs.
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        const kiln::TextureRef& light = ctx.output("lamp_transmittance");
        glUseProgram(lighter);
        kiln::gl::bindTexture(lighter, "u_fire", fire.id);
        kiln::gl::bindImage(lighter, "u_transmittance", light.id, 0, true, GL_WRITE_ONLY, GL_R16F);
        glUniform1i(glGetUniformLocation(lighter, "u_firstFireball"), GLint(scene.firstInstance(kiln::kSceneGlowingSpheres)));
        glUniform1i(glGetUniformLocation(lighter, "u_fireballCount"), GLint(scene.count(kiln::kSceneGlowingSpheres)));
        glDispatchCompute(groups(light.width), groups(light.height), groups(light.depth));
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    }

    // fire_cover: `fire`'s mips, each level the mean of the one below (voxelize/fire_mip.comp).
    static void mipFire(kiln::PassContext& ctx, GLuint program) {
        const kiln::TextureRef& fire = ctx.output("fire");
        glUseProgram(program);
        for (int level = 1; level < fire.levels; ++level) {
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            kiln::gl::bindImage(program, "u_finer", fire.id, level - 1, true, GL_READ_ONLY, GL_R16F);
            kiln::gl::bindImage(program, "u_coarser", fire.id, level, true, GL_WRITE_ONLY, GL_R16F);
            glDispatchCompute(groups(std::max(1, fire.width >> level)), groups(std::max(1, fire.height >> level)),
                              groups(std::max(1, fire.depth >> level)));
        }
    }

    // The tumblers from their exact shape (tumbler_mode splat): one invocation per voxel of
    // the cube around each one's bounding ball (half its height plus its lower radius
    // from the axis' midpoint), a row of groups per tumbler.
    static void splatTumblerShapes(kiln::PassContext& ctx, GLuint program, glm::ivec3 res) {
        const kiln::SceneView& scene = ctx.scene();
        const uint32_t tumblers = scene.count(kiln::kSceneRoundCones);
        if (tumblers == 0) return;
        const glm::vec4& shape = scene.frame.roundCone;
        // The smallest cell side: the cube of cells around the ball covers it on every axis.
        const glm::vec3 cell = 2.0f * scene.frame.voxelVolume.w * glm::vec3(scene.frame.voxelExtent) / glm::vec3(res);
        const float reach = 0.5f * shape.w + shape.x, voxel = std::min({cell.x, cell.y, cell.z});
        const int side = std::min(std::max({res.x, res.y, res.z}), int(std::ceil(2.0f * reach / voxel)) + 1);  // +1: the cube starts at a floor
        useSurfaceProgram(ctx, program, res);
        glUniform1ui(glGetUniformLocation(program, "u_first"), scene.firstInstance(kiln::kSceneRoundCones));
        glUniform1i(glGetUniformLocation(program, "u_side"), side);
        glDispatchCompute(GLuint((side * side * side + 63) / 64), tumblers, 1);
    }

    // 4: the sums' averages into the outputs.
    static void resolveSums(kiln::PassContext& ctx, GLuint resolve, const kiln::TextureRef& out, glm::ivec3 res) {
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        glUseProgram(resolve);
        bindSums(ctx, resolve, GL_READ_ONLY);
        kiln::gl::bindTexture(resolve, "u_lampTransmittance", ctx.output("lamp_transmittance").id);  // fire_cover on
        kiln::gl::bindImage(resolve, "u_radiance", out.id, 0, true, GL_WRITE_ONLY, GL_RGBA16F);
        kiln::gl::bindImage(resolve, "u_albedo", ctx.output("albedo").id, 0, true, GL_WRITE_ONLY, GL_RGBA8);
        kiln::gl::bindImage(resolve, "u_normal", ctx.output("normal").id, 0, true, GL_WRITE_ONLY, GL_RGBA16F);
        glDispatchCompute(groups(res.x), groups(res.y), groups(res.z));
    }
    static GLuint groups(int n) { return GLuint((n + 3) / 4); }  // 4³ workgroups

    // The accumulators: one volume, kSumChannels grids along x (shaders/voxelize/sums.glsl).
    static constexpr int kSumChannels = 14;
    static void bindSums(kiln::PassContext& ctx, GLuint program, GLenum access) {
        kiln::gl::bindImage(program, "u_sums", ctx.internal("sums").id, 0, true, access, GL_R32UI);
    }

    // lamp_model field: the lamp's vector irradiance on its grid (the same builder as
    // composite's), rebuilt when the lamp, the texture or the builder changed. False when
    // the pass failed.
    static constexpr int kLampFieldSide = 256;
    bool buildLampField(kiln::PassContext& ctx) {
        GLuint builder = ctx.program({.stages = {"common/lamp_field.comp"}, .defines = {{"KILN_LAMP_SAMPLES", "16"}}});
        if (!builder) return false;
        const kiln::TextureRef& field = ctx.internal("lamp_field");
        const FieldKey key{ctx.scene().version(kiln::kSceneLights), field.id, builder};
        if (key == builtField_) return true;
        glUseProgram(builder);
        kiln::gl::bindImage(builder, "u_field", field.id, 0, false, GL_WRITE_ONLY, GL_RG16F);
        glDispatchCompute(GLuint((field.width + 7) / 8), GLuint((field.height + 7) / 8), 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
        builtField_ = key;
        return true;
    }
    struct FieldKey {
        uint64_t lightVersion = 0;
        GLuint texture = 0, program = 0;
        bool operator==(const FieldKey&) const = default;
    };
    FieldKey builtField_;
    // What `static_sums` and the recorded fragments were last built from (a cache: a
    // module reload starts over).
    struct StaticKey {
        uint64_t lampVersion = 0, lightVersion = 0, boxVersion = 0, meshesVersion = 0;
        glm::vec4 ringsLight{-1.0f}, ringsDark{-1.0f};  // the floor's grain (its albedo)
        glm::vec4 volume{0.0f}, extent{0.0f};
        GLuint texture = 0, program = 0, recorder = 0;
        glm::ivec3 grid{0};
        float emission = -1.0f;
        bool conservative = false;
        bool operator==(const StaticKey&) const = default;
    };
    StaticKey builtStatic_;
    // The walls' fragments (shaders/voxelize/static_surfaces.glsl): a 16-byte header, then
    // 64 bytes each: 5 435 at 32³ (0.3 MiB), 83 195 at 128³ (5.1 MiB), under 5 (res + 2)².
    static constexpr GLuint kStaticBinding = 3;
    static constexpr GLsizeiptr kStaticHeaderBytes = 16, kStaticFragmentBytes = 64;
    kiln::gl::Buffer staticFragments_;
    GLsizeiptr staticCapacity_ = 0;
    GLuint staticRecorded_ = 0;

    kiln::gl::FramebufferHandle fbo_;  // attachment-less; a GL cache only (a reload makes a new one)
    int fboSize_ = 0;
    static constexpr int kRasterTile = 64;  // llvmpipe shades a framebuffer in tiles of 64², one thread each
    // splat.comp's workgroups. The fireballs are few and each costs many voxels' lighting:
    // eight to a group spreads fifty over llvmpipe's threads, where 64 put them all on
    // one, which is slower.
    static constexpr uint32_t kFireballGroup = 8, kParticleGroup = 64;
};

}  // namespace

KILN_PASS_MODULE(voxelize, Voxelize)
