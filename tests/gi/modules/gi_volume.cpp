// gi_volume — a test-only pass that writes a known voxel volume (the shape of
// voxelize.radiance: premultiplied rgb, opacity in a) so the mip and cone-trace passes
// can be checked against hand-computed values.
//   solid          every voxel (0.6, 0.3, 0.15, 1)
//   layers         two-layer slabs across x: even x (0.5, 0, 0, 0.5) — red, half opaque
//                  — odd x (0, 1, 0, 1) — green, opaque
//   emissive_wall  the five walls of the Cornell box (outermost voxel layers except
//                  z = max, the open front) opaque and black, the left wall (x = 0)
//                  emitting (1, 1, 1)
#include <kiln/pass.hpp>

#include <vector>

namespace {

class GiVolume final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "radiance", .kind = TextureKind::Color3D, .format = Format::RGBA16F,
                  .size = SizeRule::fromParam("resolution")})
            .param(intChoiceParam("resolution", 32, {8, 16, 32, 64}))
            .param(enumParam("pattern", "solid", {"solid", "layers", "emissive_wall"}));
        return d;
    }
    void execute(kiln::PassContext& ctx) override {
        const kiln::TextureRef& out = ctx.output("radiance");
        const int n = out.width;
        const std::string& pattern = ctx.getEnum("pattern");
        std::vector<float> v(size_t(n) * n * n * 4, 0.0f);
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    float* p = &v[((size_t(z) * n + y) * n + x) * 4];
                    auto set = [&](float r, float g, float b, float a) { p[0] = r, p[1] = g, p[2] = b, p[3] = a; };
                    if (pattern == "solid") {
                        set(0.6f, 0.3f, 0.15f, 1.0f);
                    } else if (pattern == "layers") {
                        if (x % 2 == 0) set(0.5f, 0.0f, 0.0f, 0.5f);
                        else set(0.0f, 1.0f, 0.0f, 1.0f);
                    } else {
                        if (x == 0) set(1.0f, 1.0f, 1.0f, 1.0f);
                        else if (x == n - 1 || y == 0 || y == n - 1 || z == 0) set(0.0f, 0.0f, 0.0f, 1.0f);
                    }
                }
        glTextureSubImage3D(out.id, 0, 0, 0, 0, n, n, n, GL_RGBA, GL_FLOAT, v.data());
    }
};

}  // namespace

KILN_PASS_MODULE(gi_volume, GiVolume)
