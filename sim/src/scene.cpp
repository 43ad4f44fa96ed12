#include "kiln/sim/scene.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "kiln/json_path.hpp"
#include "kiln/json_text.hpp"
#include "kiln/sim/shape.hpp"

namespace kiln::sim {

using Json = nlohmann::json;

std::string SceneError::toString(const std::string& file) const {
    return path.empty() ? file + ": " + message : file + ": " + path + ": " + message;
}

namespace {

// The value as the file wrote it, at most 60 bytes of it (a 10 MB array as a "radius"
// gives a one-line error); nesting is bounded before anything is parsed, so dump()
// cannot recurse deeply.
std::string shown(const Json& v) { return json_text::elide(v.dump(), 60); }

const char* typeName(const Json& j) {
    switch (j.type()) {
        case Json::value_t::null: return "null";
        case Json::value_t::boolean: return "a boolean";
        case Json::value_t::string: return "a string";
        case Json::value_t::array: return "an array";
        case Json::value_t::object: return "an object";
        case Json::value_t::number_integer:
        case Json::value_t::number_unsigned:
        case Json::value_t::number_float: return "a number";
        default: return "something else";
    }
}

// Reads typed values out of one JSON object, remembering its path for messages and
// which keys were used so unknown ones can be reported.
struct Reader {
    const Json& j;
    std::string path;
    SceneError& error;
    std::set<std::string> known;

    std::string at(const std::string& key) const { return path.empty() ? key : path + "." + key; }
    bool fail(const std::string& where, const std::string& what) {
        error = {where, what};
        return false;
    }
    bool number(const std::string& key, double& out, double lo, double hi) {
        known.insert(key);
        if (!j.contains(key)) return true;
        const Json& v = j[key];
        if (!v.is_number()) return fail(at(key), std::string("expected a number, got ") + typeName(v));
        double d = v.get<double>();
        if (!std::isfinite(d) || d < lo || d > hi)
            return fail(at(key), "must be within [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + shown(v));
        out = d;
        return true;
    }
    bool integer(const std::string& key, int& out, int lo, int hi) {
        known.insert(key);
        if (!j.contains(key)) return true;
        const Json& v = j[key];
        if (!v.is_number_integer()) return fail(at(key), std::string("expected an integer, got ") + shown(v));
        long long n = v.get<long long>();
        if (n < lo || n > hi)
            return fail(at(key), "must be within [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + shown(v));
        out = int(n);
        return true;
    }
    template <int N>
    bool vec(const std::string& key, glm::vec<N, double>& out, double lo, double hi) {
        known.insert(key);
        if (!j.contains(key)) return true;
        const Json& v = j[key];
        if (!v.is_array() || v.size() != N)
            return fail(at(key), "expected an array of " + std::to_string(N) + " numbers, got " + shown(v));
        for (int i = 0; i < N; ++i) {
            if (!v[size_t(i)].is_number())
                return fail(at(key) + "[" + std::to_string(i) + "]", std::string("expected a number, got ") + typeName(v[size_t(i)]));
            double d = v[size_t(i)].get<double>();
            if (!std::isfinite(d) || d < lo || d > hi)
                return fail(at(key) + "[" + std::to_string(i) + "]",
                            "must be within [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + shown(v[size_t(i)]));
            out[i] = d;
        }
        return true;
    }
    bool choice(const std::string& key, const std::vector<std::string>& choices, int& out) {
        known.insert(key);
        if (!j.contains(key)) return true;
        const Json& v = j[key];
        std::string list;
        for (auto& c : choices) list += (list.empty() ? "" : ", ") + ("\"" + c + "\"");
        if (!v.is_string()) return fail(at(key), "expected one of " + list + ", got " + shown(v));
        for (size_t i = 0; i < choices.size(); ++i)
            if (v.get<std::string>() == choices[i]) {
                out = int(i);
                return true;
            }
        return fail(at(key), "expected one of " + list + ", got " + shown(v));
    }
    bool boolean(const std::string& key, bool& out) {
        known.insert(key);
        if (!j.contains(key)) return true;
        const Json& v = j[key];
        if (!v.is_boolean()) return fail(at(key), std::string("expected true or false, got ") + typeName(v));
        out = v.get<bool>();
        return true;
    }
    // Unknown keys are typos until proven otherwise.
    bool finish() {
        known.insert("note");
        known.insert("$schema");
        for (auto& [k, v] : j.items())
            if (!known.count(k)) return fail(at(json_text::elide(k, 60)), "unknown key");
        return true;
    }
};

bool object(const Json& root, const std::string& key, const std::string& path, SceneError& error, const Json*& out) {
    out = nullptr;
    if (!root.contains(key)) return true;
    if (!root[key].is_object()) {
        error = {path, std::string("expected an object, got ") + typeName(root[key])};
        return false;
    }
    out = &root[key];
    return true;
}

bool balls(const Json& root, const std::string& key, std::vector<Scene::BallSpec>& out, double defaultRadius,
           SceneError& error) {
    if (!root.contains(key)) return true;
    if (!root[key].is_array()) {
        error = {key, std::string("expected an array, got ") + typeName(root[key])};
        return false;
    }
    for (size_t i = 0; i < root[key].size(); ++i) {
        const Json& b = root[key][i];
        const std::string path = key + "[" + std::to_string(i) + "]";
        if (!b.is_object()) {
            error = {path, std::string("expected an object, got ") + typeName(b)};
            return false;
        }
        Scene::BallSpec spec;
        spec.radius = defaultRadius;
        Reader r{b, path, error, {}};
        if (!r.vec<3>("position", spec.position, -1.0, 1.0) || !r.vec<3>("velocity", spec.velocity, -100.0, 100.0) ||
            !r.number("radius", spec.radius, 0.005, 0.3) || !r.vec<3>("color", spec.color, 0.0, 100.0) || !r.finish())
            return false;
        if (!b.contains("position")) {
            error = {path + ".position", "missing (a ball needs a position)"};
            return false;
        }
        for (int a = 0; a < 3; ++a)
            if (std::abs(spec.position[a]) > 1.0 - spec.radius) {
                error = {path + ".position", "the ball (radius " + b.value("radius", Json(spec.radius)).dump() +
                                                 ") does not fit inside the box [-1,1]^3"};
                return false;
            }
        out.push_back(spec);
    }
    return true;
}

// The models the scene places (the renderer draws them; the simulation's bodies do not
// collide with them).
bool models(const Json& root, std::vector<Scene::ModelSpec>& out, SceneError& error) {
    if (!root.contains("models")) return true;
    if (!root["models"].is_array()) {
        error = {"models", std::string("expected an array, got ") + typeName(root["models"])};
        return false;
    }
    if (root["models"].size() > kMaxModels) {
        error = {"models", "more than " + std::to_string(kMaxModels) + " models"};
        return false;
    }
    for (size_t i = 0; i < root["models"].size(); ++i) {
        const Json& m = root["models"][i];
        const std::string path = "models[" + std::to_string(i) + "]";
        if (!m.is_object()) {
            error = {path, std::string("expected an object, got ") + typeName(m)};
            return false;
        }
        Scene::ModelSpec spec;
        Reader r{m, path, error, {"file"}};
        if (!m.contains("file") || !m["file"].is_string() || m["file"].get<std::string>().empty()) {
            error = {path + ".file", "expected the glTF file's path (relative to the scene file), got " +
                                         (m.contains("file") ? shown(m["file"]) : std::string("nothing"))};
            return false;
        }
        spec.file = m["file"].get<std::string>();
        if (!r.vec<3>("position", spec.position, -1e4, 1e4) || !r.number("scale", spec.scale, 1e-6, 1e6) ||
            !r.vec<3>("rotation_deg", spec.rotationDeg, -360.0, 360.0) || !r.boolean("fit", spec.fit) || !r.finish())
            return false;
        out.push_back(spec);
    }
    return true;
}

bool restitution(const Json& physics, Scene::Physics::Restitution& e, SceneError& error) {
    const Json* o = nullptr;
    if (!object(physics, "restitution", "physics.restitution", error, o)) return false;
    if (!o) return true;
    Reader r{*o, "physics.restitution", error, {}};
    return r.number("ball_box", e.ballBox, 0, 1) && r.number("ball_lamp", e.ballLamp, 0, 1) &&
           r.number("ball_ball", e.ballBall, 0, 1) && r.number("ball_tumbler", e.ballTumbler, 0, 1) &&
           r.number("tumbler_tumbler", e.tumblerTumbler, 0, 1) && r.number("tumbler_floor", e.tumblerFloor, 0, 1) &&
           r.finish();
}

using json_text::lineColumn;


// Parses the JSON text; a syntax error becomes "line L, column C: ...". Every exception
// the JSON library throws (syntax, a number beyond double range, ...) becomes an error
// here: none escapes to the caller.
bool parseJson(const std::string& text, Json& root, SceneError& error) {
    int line = 1, column = 1;
    if (const size_t at = json_text::firstTooDeep(text, kMaxSceneNesting); at != std::string::npos) {
        lineColumn(text, at, line, column);
        error = {"", "line " + std::to_string(line) + ", column " + std::to_string(column) + ": nested deeper than " +
                         std::to_string(kMaxSceneNesting) + " levels"};
        return false;
    }
    // Where the parser was when the library refused a value (a number beyond double
    // range): "physics.dt", "marbles[3].position[1]".
    json_text::PathTracker tracker;
    try {
        root = Json::parse(text, std::ref(tracker));
    } catch (const Json::parse_error& e) {
        // Byte offset → line and column.
        lineColumn(text, e.byte > 0 ? e.byte - 1 : 0, line, column);
        // what(): "[json.exception.parse_error.101] parse error at line 1, column 5: syntax
        // error while parsing ...; last read: '...'": the part after the position (the
        // quoted token may itself hold ": ").
        std::string what = e.what();
        const size_t p = what.find("parse error");
        const size_t colon = p == std::string::npos ? std::string::npos : what.find(": ", p);
        error = {"", "line " + std::to_string(line) + ", column " + std::to_string(column) + ": " +
                         json_text::elide(colon == std::string::npos ? what : what.substr(colon + 2), 160)};
        return false;
    } catch (const Json::exception& e) {
        // out_of_range 406 "number overflow parsing '1e999'": locate the quoted token.
        std::string what = e.what();
        const size_t bracket = what.find("] ");
        if (bracket != std::string::npos) what = what.substr(bracket + 2);
        std::string where;
        const size_t open = what.find('\''), close = what.rfind('\'');
        if (open != std::string::npos && close > open + 1) {
            const size_t at = text.find(what.substr(open + 1, close - open - 1));
            if (at != std::string::npos) {
                lineColumn(text, at, line, column);
                where = "line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
            }
        }
        if (e.id == 406) what += " (beyond the range of a double)";
        error = {tracker.path(), where + json_text::elide(what, 160)};
        return false;
    }
    if (!root.is_object()) {
        error = {"", std::string("the scene must be a JSON object, got ") + typeName(root)};
        return false;
    }
    // nlohmann keeps the last of two equal keys: a second "physics" block would silently
    // win over the first.
    if (!tracker.duplicateKeys().empty()) {
        error = {tracker.duplicateKeys().front(), "duplicate key: only the last one would count"};
        return false;
    }
    return true;
}

// A list longer than its limit is refused before any entry is read.
bool withinLimit(const Json& root, const char* key, size_t limit, const char* what, SceneError& error) {
    if (!root.contains(key) || !root[key].is_array() || root[key].size() <= limit) return true;
    error = {key, std::to_string(root[key].size()) + " " + what + ", more than the limit of " + std::to_string(limit)};
    return false;
}

bool readBox(const Json& root, Scene& s, SceneError& error) {
    const Json* o = nullptr;
    if (!object(root, "box", "box", error, o)) return false;
    if (o) {
        Reader r{*o, "box", error, {}};
        if (!r.vec<3>("left", s.box.left, 0, 1) || !r.vec<3>("right", s.box.right, 0, 1) ||
            !r.vec<3>("other", s.box.other, 0, 1) || !r.vec<3>("emission", s.box.emission, 0, 1e4) ||
            !r.boolean("closed", s.box.closed) || !r.boolean("walls", s.box.walls))
            return false;
        s.box.lamp = s.box.walls;
        if (!r.boolean("lamp", s.box.lamp)) return false;
        r.known.insert("floor_wood");
        const Json* w = nullptr;
        if (!object(*o, "floor_wood", "box.floor_wood", error, w)) return false;
        if (w) {
            Reader rw{*w, "box.floor_wood", error, {}};
            if (!rw.vec<3>("light", s.box.floorWood.light, 0, 1) || !rw.vec<3>("dark", s.box.floorWood.dark, 0, 1) ||
                !rw.number("ring_frequency", s.box.floorWood.ringFrequency, 0, 1000) || !rw.finish())
                return false;
        }
        if (!r.finish()) return false;
    }
    return true;
}

bool readLamp(const Json& root, Scene& s, SceneError& error) {
    const Json* o = nullptr;
    if (!object(root, "lamp", "lamp", error, o)) return false;
    if (o) {
        Reader r{*o, "lamp", error, {}};
        if (!r.vec<3>("center", s.lamp.center, -2, 3) || !r.number("radius", s.lamp.radius, 0.01, 0.9) ||
            !r.vec<3>("color", s.lamp.color, 0, 1) || !r.number("intensity", s.lamp.intensity, 0, 1e4) || !r.finish())
            return false;
    }
    return true;
}

bool readPhysics(const Json& root, Scene& s, SceneError& error) {
    const Json* o = nullptr;
    if (!object(root, "physics", "physics", error, o)) return false;
    if (o) {
        Reader r{*o, "physics", error, {"restitution"}};
        int mode = int(s.physics.tumblerMode), contact = int(s.physics.tumblerContact);
        double seed = double(s.physics.seed);
        if (!r.number("dt", s.physics.dt, 1e-5, 0.1) || !r.integer("substeps", s.physics.substeps, 1, 64) ||
            !r.integer("max_substeps", s.physics.maxSubsteps, 1, 4096) ||
            !r.number("gravity", s.physics.gravity, 0, 100) || !r.number("friction", s.physics.friction, 0, 10) ||
            !r.number("wall_decay", s.physics.wallDecay, 0, 1) || !r.boolean("balls_keep_speed", s.physics.ballsKeepSpeed) ||
            !r.choice("tumbler_mode", {"course", "accurate"}, mode) ||
            !r.choice("tumbler_contact", {"four_spheres", "exact"}, contact) ||
            !r.number("ballast_h", s.physics.ballastH, -0.19, 0.19) || !r.number("seed", seed, 0, 4294967295.0) || !r.finish())
            return false;
        if (!restitution(*o, s.physics.restitution, error)) return false;
        // Sub-steps longer than kMaxFixedSubstep were unstable: a tumbler spun by ball
        // hits gained energy without bound (NaN within 60 frames at Δt 0.1 in a crowded
        // box). Adaptive sub-stepping never goes above it (World::substepsFor); a scene
        // whose sub-step count cannot reach it is refused.
        const bool adaptive = s.physics.maxSubsteps > s.physics.substeps;
        const int most = std::max(s.physics.substeps, s.physics.maxSubsteps);
        const int needed = int(std::ceil(s.physics.dt / kMaxFixedSubstep - 1e-9));
        if (most < needed) {
            const std::string substep = std::to_string(s.physics.dt / most * 1000.0).substr(0, 6) + " ms";
            error = {"physics.max_substeps",
                     (adaptive ? "max_substeps " + std::to_string(most) + " allows sub-steps of dt/max_substeps = " + substep
                               : "adaptive sub-steps are off (max_substeps " + std::to_string(s.physics.maxSubsteps) +
                                     " <= substeps " + std::to_string(s.physics.substeps) + ") and a fixed sub-step of dt/substeps = " +
                                     substep) +
                         ", longer than the 4.17 ms (1/240 s) that stays stable: " +
                         (adaptive ? "set max_substeps to at least " + std::to_string(needed)
                                   : "set substeps to at least " + std::to_string(needed) + ", or max_substeps above substeps")};
            return false;
        }
        s.physics.tumblerMode = TumblerMode(mode);
        s.physics.tumblerContact = TumblerContact(contact);
        s.physics.seed = uint64_t(seed);
    }
    return true;
}

bool readShape(const Json& root, Scene& s, SceneError& error) {
    const Json* o = nullptr;
    if (!object(root, "tumbler_shape", "tumbler_shape", error, o)) return false;
    if (o) {
        Reader r{*o, "tumbler_shape", error, {}};
        double alphaDeg = s.tumblerShape.alpha * 180.0 / 3.14159265358979323846;
        if (!r.number("b", s.tumblerShape.b, 0.02, 0.4) || !r.number("t", s.tumblerShape.t, 0.01, 0.4) ||
            !r.number("alpha_deg", alphaDeg, 1, 80) || !r.number("mass", s.tumblerShape.mass, 1e-3, 1e3) || !r.finish())
            return false;
        if (s.tumblerShape.t >= s.tumblerShape.b) {
            error = {"tumbler_shape.t", "must be smaller than b (the upper sphere sits on the lower one)"};
            return false;
        }
        s.tumblerShape.alpha = alphaDeg * 3.14159265358979323846 / 180.0;
    }
    return true;
}

bool readTumblers(const Json& root, Scene& s, SceneError& error) {
    if (!root.contains("tumblers") || !root["tumblers"].is_array()) {
        error = {"tumblers", root.contains("tumblers") ? std::string("expected an array, got ") + typeName(root["tumblers"])
                                                       : "missing (the list of tumblers, possibly empty)"};
        return false;
    }
    const double b = s.tumblerShape.b;
    for (size_t i = 0; i < root["tumblers"].size(); ++i) {
        const Json& t = root["tumblers"][i];
        const std::string path = "tumblers[" + std::to_string(i) + "]";
        if (!t.is_object()) {
            error = {path, std::string("expected an object, got ") + typeName(t)};
            return false;
        }
        Scene::TumblerSpec spec;
        Reader r{t, path, error, {}};
        if (!r.vec<2>("position", spec.position, -1, 1) || !r.vec<2>("tilt", spec.tilt, -1.5, 1.5) ||
            !r.vec<3>("color", spec.color, 0, 1) || !r.finish())
            return false;
        if (!t.contains("position")) {
            error = {path + ".position", "missing (a tumbler needs a position [x, z] on the floor)"};
            return false;
        }
        if (std::abs(spec.position.x) > 1.0 - b || std::abs(spec.position.y) > 1.0 - b) {
            error = {path + ".position", "a tumbler of radius " + std::to_string(b) + " at this spot pokes out of the box"};
            return false;
        }
        s.tumblers.push_back(spec);
    }
    return true;
}

// With its tilt, the upper sphere must be inside too, and no two tumblers may overlap.
bool checkTumblerPoses(const Scene& s, SceneError& error) {
    const auto& ts = s.tumblerShape;
    const RoundCone shape(ts.b, ts.t, ts.alpha);
    std::vector<std::pair<glm::dvec3, glm::dvec3>> axes;
    for (size_t i = 0; i < s.tumblers.size(); ++i) {
        const auto& spec = s.tumblers[i];
        const glm::dvec3 o(spec.position.x, -1.0 + ts.b, spec.position.y);
        const glm::dquat q = glm::angleAxis(spec.tilt.y, glm::dvec3(0, 0, 1)) * glm::angleAxis(spec.tilt.x, glm::dvec3(1, 0, 0));
        const glm::dvec3 top = o + q * glm::dvec3(0, shape.upperCentre(), 0);
        const std::string path = "tumblers[" + std::to_string(i) + "]";
        for (int a = 0; a < 3; ++a)
            if (std::abs(top[a]) > 1.0 - ts.t || (a == 1 && top.y < -1.0 + ts.t)) {
                error = {path + ".tilt", "with this tilt the tumbler's upper sphere is outside the box"};
                return false;
            }
        for (size_t j = 0; j < axes.size(); ++j)
            if (roundConeSeparation(axes[j].first, axes[j].second, ts.b, ts.t, o, top, ts.b, ts.t).distance < 0.0) {
                error = {path + ".position", "overlaps tumblers[" + std::to_string(j) + "]"};
                return false;
            }
        axes.emplace_back(o, top);
    }
    return true;
}

}  // namespace

static bool readScene(const Json& root, Scene& out, SceneError& error);

bool parseScene(const std::string& text, Scene& out, SceneError& error) {
    Json root;
    if (!parseJson(text, root, error)) return false;
    try {
        return readScene(root, out, error);
    } catch (const std::exception& e) {  // no library exception crosses the loader
        error = {"", std::string("cannot read the scene: ") + json_text::elide(e.what(), 160)};
        return false;
    }
}

static bool readScene(const Json& root, Scene& out, SceneError& error) {
    Scene s;
    if (!withinLimit(root, "tumblers", kMaxTumblers, "tumblers", error) ||
        !withinLimit(root, "marbles", kMaxMarbles, "marbles", error) ||
        !withinLimit(root, "fireballs", kMaxFireballs, "fireballs", error))
        return false;
    if (!readBox(root, s, error) || !readLamp(root, s, error) || !readPhysics(root, s, error) ||
        !readShape(root, s, error) || !readTumblers(root, s, error) || !checkTumblerPoses(s, error))
        return false;
    if (!balls(root, "marbles", s.marbles, 0.05, error) || !balls(root, "fireballs", s.fireballs, 0.06, error) ||
        !models(root, s.models, error))
        return false;
    Reader top{root, "", error,
               {"box", "lamp", "physics", "tumbler_shape", "tumblers", "marbles", "fireballs", "models", "$schema"}};
    if (!top.finish()) return false;
    // The bodies are the box's: they stand on its floor and bounce off its walls.
    if (!s.box.walls && (!s.tumblers.empty() || !s.marbles.empty() || !s.fireballs.empty())) {
        error = {"box.walls", "false, but the scene has " + std::to_string(s.tumblers.size()) + " tumblers, " +
                                  std::to_string(s.marbles.size()) + " marbles and " + std::to_string(s.fireballs.size()) +
                                  " fireballs: they live in the box (remove them, or keep the walls)"};
        return false;
    }
    out = std::move(s);
    return true;
}

SceneResult parseSceneText(const std::string& text) {
    SceneResult r;
    r.valid = parseScene(text, r.scene, r.error);
    return r;
}

SceneResult loadSceneFile(const std::string& path) {
    SceneResult r;
    std::string text, why;
    if (!json_text::readBoundedFile(path, kMaxSceneFileBytes, "scene file", text, why)) {
        r.error = {"", why};
        return r;
    }
    return parseSceneText(text);
}

bool loadScene(const std::string& path, Scene& out, std::string& error) {
    SceneResult r = loadSceneFile(path);
    if (!r) {
        error = r.error.toString(path);
        return false;
    }
    out = std::move(r.scene);
    return true;
}

}  // namespace kiln::sim
