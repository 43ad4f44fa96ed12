// run/pass_slot.hpp — everything the host keeps for one pass of the running plan: the
// object (from its module), its textures and framebuffers, its programs, the key of
// its last run (to skip it) and its timings. The host owns all of it, so a module
// reload or a parameter change swaps the object and keeps the rest.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kiln/module_loader.hpp"
#include "run/pass_stats.hpp"
#include "run/program_cache.hpp"
#include "run/texture_pool.hpp"

namespace kiln::run {

struct PassSlot {
    std::string id, module;
    uint64_t signature = 0;
    std::shared_ptr<LoadedModule> library;
    PassPtr pass;
    PassTextures textures;
    std::map<std::string, gl::FramebufferHandle> framebuffers;
    ProgramCache programs;
    std::optional<std::vector<uint64_t>> lastRunKey;  // empty: run next frame
    int settlingFrames = 0;                           // runs left that keepRunning asked for
    bool lastRunByScene = false;                      // its last run changed only what bodies moving change
    int convergingRuns = 0;                           // runs left of settling after a change to everything
    uint64_t setup = 0;                               // its textures' TextureRef::setup
    std::vector<uint64_t> inputSetups;                // each input's setup at its last run
    std::string settlingReason;
    std::string error;                                // why the last execute failed
    std::string loggedError;                          // the last error printed (once each)
    PassTimings timings;

    // Forget the last run (the pass runs next frame) and, when its textures changed,
    // the framebuffers over them.
    void invalidate(bool texturesChanged) {
        lastRunKey.reset();
        if (texturesChanged) framebuffers.clear();
    }
};

}  // namespace kiln::run
