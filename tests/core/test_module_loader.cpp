#include <catch2/catch.hpp>

#include <dlfcn.h>

#include "kiln/module_loader.hpp"

using kiln::ModuleLoader;

TEST_CASE("module loader loads a real module and its declaration", "[loader]") {
    ModuleLoader loader({TEST_MODULE_DIR});
    std::string error;
    auto module = loader.load("test_good", error);
    REQUIRE(module);
    CHECK(error.empty());
    CHECK(module->descriptor().abiVersion == kiln::kPassAbiVersion);
    auto pass = ModuleLoader::create(module, error);
    REQUIRE(pass);
    auto decl = pass->declare();
    REQUIRE(decl.outputs.size() == 1);
    CHECK(decl.outputs[0].name == "color");
    REQUIRE(decl.params.size() == 1);
    CHECK(std::get<float>(decl.params[0].def) == 2.0f);
}

TEST_CASE("module loader: a missing module lists what exists and suggests", "[loader]") {
    ModuleLoader loader({TEST_MODULE_DIR});
    std::string error;
    CHECK_FALSE(loader.load("test_goood", error));
    CHECK_THAT(error, Catch::Contains("no module \"test_goood\""));
    CHECK_THAT(error, Catch::Contains("did you mean \"test_good\""));
    CHECK_THAT(error, Catch::Contains("available: bad_abi, bad_factory, not_a_module, test_good"));
}

TEST_CASE("module loader: a .so without the entry symbol is not a module", "[loader]") {
    ModuleLoader loader({TEST_MODULE_DIR});
    std::string error;
    CHECK_FALSE(loader.load("not_a_module", error));
    CHECK_THAT(error, Catch::Contains("libpass_not_a_module.so"));
    CHECK_THAT(error, Catch::Contains("not a Kiln pass module"));
}

TEST_CASE("module loader: ABI mismatch names both versions", "[loader]") {
    ModuleLoader loader({TEST_MODULE_DIR});
    std::string error;
    CHECK_FALSE(loader.load("bad_abi", error));
    CHECK_THAT(error, Catch::Contains("ABI version 999"));
    CHECK_THAT(error, Catch::Contains("version " + std::to_string(kiln::kPassAbiVersion)));
}

TEST_CASE("module loader: a throwing factory is reported, not fatal", "[loader]") {
    ModuleLoader loader({TEST_MODULE_DIR});
    std::string error;
    auto module = loader.load("bad_factory", error);
    REQUIRE(module);
    CHECK_FALSE(ModuleLoader::create(module, error));
    CHECK_THAT(error, Catch::Contains("factory failed: out of widgets"));
}

TEST_CASE("module loader refuses names with a path, .. or a suffix", "[loader]") {
    ModuleLoader loader({TEST_MODULE_DIR});
    for (const char* bad : {"../test_good", "test_good.so", "sub/test_good", "..", "", "Test_Good", "/tmp/x"}) {
        std::string error;
        INFO(bad);
        CHECK_FALSE(loader.load(bad, error));
        CHECK_THAT(error, Catch::Contains("[a-z0-9_]+"));
    }
}

TEST_CASE("module loader loads a private copy, so two loads are two libraries", "[loader]") {
    ModuleLoader loader({TEST_MODULE_DIR});
    std::string error;
    auto a = loader.load("test_good", error);
    auto b = loader.load("test_good", error);
    REQUIRE(a);
    REQUIRE(b);
    // Different code addresses: dlopen did not hand back the cached first library.
    CHECK(reinterpret_cast<const void*>(a->descriptor().create) != reinterpret_cast<const void*>(b->descriptor().create));
}
