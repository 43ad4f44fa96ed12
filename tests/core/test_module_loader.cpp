#include <catch2/catch.hpp>

#include <dlfcn.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

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
    CHECK_THAT(error, Catch::Contains("available: bad_abi, bad_factory, not_a_module, test_faulty, test_good"));
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
    CHECK_THAT(error, Catch::Contains("factory failed: exception std::runtime_error(\"out of widgets\") in create()"));
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

// What an interrupted build leaves (`truncate -s 4096 libpass_x.so`), an empty file and
// plain garbage: each is refused with a named error before dlopen, which would otherwise
// die of SIGBUS touching a segment past the end of the file.
TEST_CASE("module loader: truncated, empty and garbage files are refused before dlopen", "[loader][robust]") {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("kiln-bad-modules-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path good = fs::path(TEST_MODULE_DIR) / "libpass_test_good.so";
    const auto size = fs::file_size(good);
    REQUIRE(size > 16384);
    struct Case { const char* name; uintmax_t keep; const char* expect; };
    for (const Case c : {Case{"cut_4096", 4096, "truncated"}, Case{"cut_half", size / 2, "truncated"},
                         Case{"cut_header", 40, "no ELF header"}, Case{"empty", 0, "no ELF header"}}) {
        const fs::path file = dir / ("libpass_" + std::string(c.name) + ".so");
        fs::copy_file(good, file, fs::copy_options::overwrite_existing);
        fs::resize_file(file, c.keep);
        ModuleLoader loader({dir});
        std::string error;
        INFO(c.name);
        CHECK_FALSE(loader.load(c.name, error));
        CHECK_THAT(error, Catch::Contains(file.string() + ": cannot load: ") && Catch::Contains(c.expect));
    }
    std::ofstream(dir / "libpass_garbage.so") << std::string(8192, 'x');
    ModuleLoader loader({dir});
    std::string error;
    CHECK_FALSE(loader.load("garbage", error));
    CHECK_THAT(error, Catch::Contains("not a 64-bit ELF shared library"));
    // The intact file still loads from the same directory.
    fs::copy_file(good, dir / "libpass_test_good.so", fs::copy_options::overwrite_existing);
    CHECK(loader.load("test_good", error));
    fs::remove_all(dir);
}
