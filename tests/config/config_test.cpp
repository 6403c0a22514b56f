#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "config/simulation_config.h"

namespace convoy::config {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" does not contain \"" << part << "\"";
}

// A temp dir holding a share dir (real schemas plus an alias "python" -> python_json) and the
// experiment files.
class ConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static int counter = 0;
    root_ = fs::temp_directory_path() /
            ("convoy_config_test_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(root_);
    share_ = root_ / "share";
    dir_ = root_ / "exp";
    fs::create_directories(share_ / "schemas");
    fs::create_directories(share_ / "engines");
    fs::copy_file(fs::path(CONVOY_TEST_SHARE_DIR) / "schemas/simulation.schema.json",
                  share_ / "schemas/simulation.schema.json");
    fs::copy_file(fs::path(CONVOY_TEST_SOURCE_DIR) / "engines/python_json/schema.json",
                  share_ / "engines/python_json.schema.json");
    write(share_ / "engines/python.alias", "python_json\n");
    write(dir_ / "engine.py", "# engine\n");
    write(dir_ / "tf.py", "# tf\n");
  }
  void TearDown() override { fs::remove_all(root_); }

  static void write(const fs::path& path, const std::string& text) {
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
  }

  static json engine(const std::string& name, const std::string& type = "python_json") {
    return {{"EngineName", name}, {"EngineType", type}, {"PythonFileName", "engine.py"}};
  }
  static json minimal() { return {{"EngineConfigs", {engine("python_1")}}}; }

  SimulationConfig load(const json& doc, const std::vector<std::string>& overrides = {}) {
    write(file(), doc.dump(2));
    return load_simulation_config(file(), overrides, share_);
  }
  // The ConfigError message, or "" if loading succeeds.
  std::string error(const json& doc, const std::vector<std::string>& overrides = {}) {
    try {
      load(doc, overrides);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  fs::path file() const { return dir_ / "sim.json"; }
  std::string prefix() const { return file().string() + ": "; }

  fs::path root_, share_, dir_;
};

TEST_F(ConfigTest, DefaultsFilled) {
  const SimulationConfig c = load(minimal());
  EXPECT_EQ(c.file, file());
  EXPECT_EQ(c.dir, dir_);
  EXPECT_EQ(c.name, "simulation");
  EXPECT_EQ(c.description, "");
  EXPECT_EQ(c.loop, "FTILoop");
  EXPECT_EQ(c.process_launcher_type, "Basic");
  EXPECT_EQ(c.datapack_processor, "tf");
  EXPECT_EQ(c.argument_passing, "value");
  EXPECT_EQ(c.timeout_ns, 0);
  EXPECT_EQ(c.timestep_ns, 10'000'000);
  EXPECT_TRUE(c.functions.empty());
  EXPECT_FALSE(c.status_function.has_value());
  EXPECT_TRUE(c.warnings.empty());
  ASSERT_EQ(c.engines.size(), 1u);
  const EngineConfig& e = c.engines[0];
  EXPECT_EQ(e.name, "python_1");
  EXPECT_EQ(e.type, "python_json");
  EXPECT_EQ(e.requested_type, "python_json");
  EXPECT_EQ(e.proc_cmd, "");
  EXPECT_TRUE(e.proc_start_params.empty());
  EXPECT_TRUE(e.env_params.empty());
  EXPECT_EQ(e.launch_type, "BasicFork");
  EXPECT_EQ(e.timestep_ns, 10'000'000);
  EXPECT_EQ(e.command_timeout_s, 0);
  EXPECT_EQ(e.server_address, "");
  EXPECT_EQ(e.pointer, "/EngineConfigs/0");
  EXPECT_EQ(e.json["EngineLaunchCommand"], json({{"LaunchType", "BasicFork"}}));
  EXPECT_EQ(e.json["EngineTimestep"], 0.01);
  EXPECT_EQ(c.json["EngineConfigs"][0], e.json);
  EXPECT_EQ(c.json["SimulationTimestep"], 0.01);
  EXPECT_EQ(c.json["DataPackProcessingFunctions"], json::array());
}

TEST_F(ConfigTest, ExplicitValuesAndFractionalDurations) {
  json doc = minimal();
  doc["SimulationTimeout"] = 0.5;
  doc["SimulationTimestep"] = 0.02;
  doc["SimulationName"] = "run";
  json& e = doc["EngineConfigs"][0];
  e["EngineTimestep"] = 0.0333;
  e["EngineCommandTimeout"] = 2.5;
  e["EngineProcCmd"] = "/usr/bin/python3";
  e["EngineProcStartParams"] = {"--verbose"};
  e["EngineEnvParams"] = {"A=1", "B="};
  e["EngineLaunchCommand"] = {{"LaunchType", "EmptyLaunchCommand"}};
  e["ServerAddress"] = "localhost:23001";
  const SimulationConfig c = load(doc);
  EXPECT_EQ(c.timeout_ns, 500'000'000);
  EXPECT_EQ(c.timestep_ns, 20'000'000);
  EXPECT_EQ(c.name, "run");
  const EngineConfig& engine = c.engines[0];
  EXPECT_EQ(engine.timestep_ns, 33'300'000);
  EXPECT_EQ(engine.command_timeout_s, 2.5);
  EXPECT_EQ(engine.proc_cmd, "/usr/bin/python3");
  EXPECT_EQ(engine.proc_start_params, std::vector<std::string>{"--verbose"});
  EXPECT_EQ(engine.env_params, (std::vector<std::string>{"A=1", "B="}));
  EXPECT_EQ(engine.launch_type, "EmptyLaunchCommand");
  EXPECT_EQ(engine.server_address, "localhost:23001");
}

TEST_F(ConfigTest, SecondsToNsRounds) {
  EXPECT_EQ(seconds_to_ns(0.1), 100'000'000);
  EXPECT_EQ(seconds_to_ns(1e-9), 1);
  EXPECT_EQ(seconds_to_ns(0.4e-9), 0);
  EXPECT_EQ(seconds_to_ns(3600.000000001), 3'600'000'000'001);
  EXPECT_THROW(seconds_to_ns(1e12), std::out_of_range);
}

TEST_F(ConfigTest, Overrides) {
  json doc = minimal();
  doc["EngineConfigs"].push_back(engine("python_2"));
  const SimulationConfig c =
      load(doc, {"SimulationTimeout=2", "EngineConfigs/0/EngineTimestep=0.02",
                 "EngineConfigs.1.EngineEnvParams=[\"X=1\"]", "SimulationName=my run",
                 "SimulationDescription=", "/EngineConfigs/1/ServerAddress=localhost:9000"});
  EXPECT_EQ(c.timeout_ns, 2'000'000'000);
  EXPECT_EQ(c.engines[0].timestep_ns, 20'000'000);
  EXPECT_EQ(c.engines[1].env_params, std::vector<std::string>{"X=1"});
  EXPECT_EQ(c.name, "my run");
  EXPECT_EQ(c.description, "");
  EXPECT_EQ(c.engines[1].server_address, "localhost:9000");
  EXPECT_EQ(c.json["SimulationTimeout"], 2);
}

TEST_F(ConfigTest, OverrideIsValidated) {
  EXPECT_EQ(error(minimal(), {"SimulationTimestep=fast"}),
            prefix() + "/SimulationTimestep: must be a number, got string \"fast\"");
}

TEST_F(ConfigTest, BadOverrideSyntax) {
  EXPECT_TRUE(
      Contains(error(minimal(), {"NoEquals"}), "override \"NoEquals\": expected Key=Value"));
  EXPECT_TRUE(Contains(error(minimal(), {"=1"}), "override \"=1\""));
  EXPECT_TRUE(Contains(error(minimal(), {"EngineConfigs/3/EngineTimestep=1"}),
                       "/EngineConfigs has 1 element(s), no index \"3\""));
  EXPECT_TRUE(Contains(error(minimal(), {"EngineConfigs/0/EngineName/x=1"}),
                       "/EngineConfigs/0/EngineName is string \"python_1\""));
}

// Found by fuzz/config: an override that is not UTF-8 threw nlohmann's type_error while its
// error message was being made.
TEST_F(ConfigTest, OverrideThatIsNotUtf8) {
  const std::string bad = "SimulationName=caf\xe9";
  EXPECT_TRUE(Contains(error(minimal(), {bad}),
                       "override \"SimulationName=caf\xef\xbf\xbd\": not valid UTF-8"));
  EXPECT_TRUE(Contains(error(minimal(), {"NoEquals\xc4"}), "not valid UTF-8"));
}

TEST_F(ConfigTest, MissingFile) {
  EXPECT_THROW(load_simulation_config(dir_ / "nope.json", {}, share_), ConfigError);
  try {
    load_simulation_config(dir_ / "nope.json", {}, share_);
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "nope.json").string() + ": cannot open");
  }
}

TEST_F(ConfigTest, MalformedJsonHasLineAndColumn) {
  write(file(), "{\n  \"SimulationTimeout\": 1,\n  \"EngineConfigs\": [,]\n}\n");
  try {
    load_simulation_config(file(), {}, share_);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(Contains(e.what(), prefix() + "malformed JSON at line 3, column 21: "));
    EXPECT_TRUE(Contains(e.what(), "unexpected ','"));
  }
}

// Found by fuzz/config: a number past double's range escaped as nlohmann's out_of_range.
TEST_F(ConfigTest, NumberOutOfRangeIsMalformedJson) {
  write(file(), "{\"SimulationTimeout\": 5E555}");
  try {
    load_simulation_config(file(), {}, share_);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), prefix() + "malformed JSON: number overflow parsing '5E555'");
  }
}

TEST_F(ConfigTest, WrongTypeNamesPointer) {
  json doc = minimal();
  doc["EngineConfigs"][0]["EngineTimestep"] = "abc";
  EXPECT_EQ(error(doc),
            prefix() + "/EngineConfigs/0/EngineTimestep: must be a number, got string \"abc\"");
}

TEST_F(ConfigTest, NonPositiveTimestepRejected) {
  json doc = minimal();
  doc["EngineConfigs"][0]["EngineTimestep"] = 0;
  EXPECT_EQ(error(doc), prefix() + "/EngineConfigs/0/EngineTimestep: must be > 0, got 0");
  doc["EngineConfigs"][0]["EngineTimestep"] = -0.01;
  EXPECT_EQ(error(doc), prefix() + "/EngineConfigs/0/EngineTimestep: must be > 0, got -0.01");
  doc["EngineConfigs"][0]["EngineTimestep"] = 1e-12;  // rounds to 0 ns
  EXPECT_TRUE(Contains(error(doc), "/EngineConfigs/0/EngineTimestep: must be at least 1 ns"));
}

TEST_F(ConfigTest, AllErrorsReportedTogether) {
  json doc = minimal();
  doc["SimulationTimeout"] = -1;
  doc["DataPackProcessor"] = "xx";
  doc["EngineConfigs"][0].erase("EngineName");
  EXPECT_EQ(error(doc), prefix() +
                            "/DataPackProcessor: must be one of \"tf\", \"cg\", got \"xx\"\n" +
                            prefix() + "/SimulationTimeout: must be >= 0, got -1\n" + prefix() +
                            "/EngineConfigs/0/EngineName: is required");
  EXPECT_EQ(error(json::object()), prefix() + "/EngineConfigs: is required");
  EXPECT_EQ(error(json::array()), prefix() + "/: must be an object, got array");
}

TEST_F(ConfigTest, UnknownEngineType) {
  json doc = minimal();
  doc["EngineConfigs"].push_back(engine("other", "foo"));
  EXPECT_EQ(error(doc), prefix() +
                            "/EngineConfigs/1/EngineType: unknown engine type \"foo\" "
                            "(known: python, python_json)");
}

TEST_F(ConfigTest, AliasResolution) {
  json doc = minimal();
  doc["EngineConfigs"][0]["EngineType"] = "python";
  const SimulationConfig c = load(doc);
  EXPECT_EQ(c.engines[0].type, "python_json");
  EXPECT_EQ(c.engines[0].requested_type, "python");
  EXPECT_EQ(c.engines[0].json["PythonFileName"], (dir_ / "engine.py").string());
  // The alias brings the real type's schema with it.
  doc["EngineConfigs"][0].erase("PythonFileName");
  EXPECT_EQ(error(doc), prefix() + "/EngineConfigs/0/PythonFileName: is required");
}

TEST_F(ConfigTest, DuplicateNames) {
  json doc = minimal();
  doc["EngineConfigs"].push_back(engine("python_1"));
  EXPECT_EQ(error(doc), prefix() +
                            "/EngineConfigs/1/EngineName: duplicate engine name "
                            "\"python_1\" (also /EngineConfigs/0)");
  doc = minimal();
  doc["DataPackProcessingFunctions"] = {{{"Name", "tf_1"}, {"FileName", "tf.py"}},
                                        {{"Name", "tf_1"}, {"FileName", "tf.py"}}};
  EXPECT_EQ(error(doc), prefix() +
                            "/DataPackProcessingFunctions/1/Name: duplicate function name "
                            "\"tf_1\" (also /DataPackProcessingFunctions/0)");
}

TEST_F(ConfigTest, NameProblems) {
  for (const std::string ok : {"python_1", "my engine", "car.v2", "Fahrzeug_ä", "a.b-c"}) {
    EXPECT_EQ(name_problem(ok), "") << ok;
  }
  EXPECT_TRUE(Contains(name_problem(""), "must not be empty"));
  for (const std::string bad : {"../x", "..", "a/b", "/abs", "a\\b", "x..y"}) {
    EXPECT_TRUE(Contains(name_problem(bad), "must not contain '/', '\\' or '..'")) << bad;
  }
  EXPECT_TRUE(Contains(name_problem(std::string("a\0b", 3)), "\"a\\u0000b\""));
  EXPECT_TRUE(Contains(name_problem("a\nb"), "control characters"));
  EXPECT_EQ(name_problem(std::string(kMaxNameBytes, 'x')), "");
  EXPECT_TRUE(Contains(name_problem(std::string(kMaxNameBytes + 1, 'x')),
                       "must be at most 200 bytes long"));
}

// Names that become file names in the run folder: each is checked where it is in the file.
TEST_F(ConfigTest, NamesThatWouldLeaveTheRunFolder) {
  json doc = minimal();
  doc["EngineConfigs"].push_back(engine("../x"));
  EXPECT_EQ(error(doc), prefix() +
                            "/EngineConfigs/1/EngineName: must not contain '/', '\\' or '..' (it "
                            "becomes part of a file name in the run folder), got \"../x\"");
  doc = minimal();
  doc["SimulationName"] = "../../escape";
  EXPECT_TRUE(Contains(error(doc), prefix() + "/SimulationName: must not contain '/'"));
  doc["SimulationName"] = "";
  EXPECT_TRUE(Contains(error(doc), prefix() + "/SimulationName: must not be empty"));
  doc["SimulationName"] = "My experiment 2";  // spaces are fine
  EXPECT_EQ(error(doc), "");
  doc = minimal();
  doc["DataPackProcessingFunctions"] = {{{"Name", "tf/../../x"}, {"FileName", "tf.py"}}};
  EXPECT_TRUE(Contains(error(doc), prefix() + "/DataPackProcessingFunctions/0/Name: must not"));
  doc = minimal();
  doc["StatusFunction"] = {{"Name", std::string("st\0x", 4)}, {"FileName", "tf.py"}};
  EXPECT_TRUE(Contains(error(doc), prefix() + "/StatusFunction/Name: must not contain NUL"));
  // Overrides are checked as well.
  EXPECT_TRUE(Contains(error(minimal(), {"EngineConfigs/0/EngineName=a/b"}),
                       prefix() + "/EngineConfigs/0/EngineName: must not contain '/'"));
}

TEST_F(ConfigTest, TooManyEngines) {
  json doc = minimal();
  doc["EngineConfigs"] = json::array();
  for (size_t i = 0; i < kMaxEngines; ++i)
    doc["EngineConfigs"].push_back(engine("e" + std::to_string(i)));
  EXPECT_EQ(load(doc).engines.size(), kMaxEngines);
  doc["EngineConfigs"].push_back(engine("one_more"));
  EXPECT_EQ(error(doc), prefix() + "/EngineConfigs: 1025 engines, more than the limit of 1024");
}

// A config file above kMaxConfigBytes is refused by its size, before it is read: a sparse
// 1 GiB file costs no disk and no time.
TEST_F(ConfigTest, OversizedConfigFileRefused) {
  write(file(), minimal().dump());
  fs::resize_file(file(), size_t{1} << 30);
  try {
    load_simulation_config(file(), {}, share_);
    FAIL() << "an oversized config was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), prefix() +
                                         "too large (1073741824 bytes; the limit for a config "
                                         "file is 64 MiB)");
  }
  fs::resize_file(file(), kMaxConfigBytes + 1);
  EXPECT_THROW(load_simulation_config(file(), {}, share_), ConfigError);
}

// Not a regular file: read up to the limit, not forever.
TEST_F(ConfigTest, EndlessConfigStreamRefused) {
  try {
    load_simulation_config("/dev/zero", {}, share_);
    FAIL() << "/dev/zero was read as a config";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(Contains(e.what(), "/dev/zero: too large (more than 67108864 bytes"));
  }
}

TEST_F(ConfigTest, MissingFiles) {
  json doc = minimal();
  doc["EngineConfigs"][0]["PythonFileName"] = "missing.py";
  EXPECT_EQ(error(doc), prefix() + "/EngineConfigs/0/PythonFileName: file not found: " +
                            (dir_ / "missing.py").string());
  doc = minimal();
  doc["DataPackProcessingFunctions"] = {{{"Name", "tf_1"}, {"FileName", "tfs/missing_tf.py"}}};
  EXPECT_EQ(error(doc), prefix() + "/DataPackProcessingFunctions/0/FileName: file not found: " +
                            (dir_ / "tfs/missing_tf.py").string());
}

TEST_F(ConfigTest, UnknownKeysWarn) {
  json doc = minimal();
  doc["EngineConfigs"][0]["EngineTimestepp"] = 0.02;
  doc["SimulationTimout"] = 5;
  const SimulationConfig c = load(doc);
  EXPECT_EQ(c.warnings,
            (std::vector<std::string>{
                prefix() + "/SimulationTimout: unknown key (ignored), did you mean "
                           "\"SimulationTimeout\"?",
                prefix() + "/EngineConfigs/0/EngineTimestepp: unknown key (ignored), did you "
                           "mean \"EngineTimestep\"?"}));
  EXPECT_EQ(c.engines[0].timestep_ns, 10'000'000);
  EXPECT_EQ(c.json["SimulationTimout"], 5);  // kept, ignored
}

TEST_F(ConfigTest, RelativePathsResolvedAgainstConfigDir) {
  write(dir_ / "scripts/engine.py", "");
  write(dir_ / "tfs/tf.py", "");
  json doc = {{"EngineConfigs",
               {{{"EngineName", "e"},
                 {"EngineType", "python_json"},
                 {"PythonFileName", "./sub/../scripts/engine.py"}}}},
              {"DataPackProcessingFunctions",
               {{{"Name", "tf_1"}, {"FileName", "tfs/tf.py"}},
                {{"Name", "tf_2"}, {"FileName", (dir_ / "tf.py").string()}, {"IsActive", false}}}},
              {"StatusFunction", {{"Name", "status"}, {"FileName", "tf.py"}}}};
  const SimulationConfig c = load(doc);
  EXPECT_EQ(c.engines[0].json["PythonFileName"], (dir_ / "scripts/engine.py").string());
  ASSERT_EQ(c.functions.size(), 2u);
  EXPECT_EQ(c.functions[0].name, "tf_1");
  EXPECT_EQ(c.functions[0].file, dir_ / "tfs/tf.py");
  EXPECT_TRUE(c.functions[0].active);
  EXPECT_EQ(c.functions[0].pointer, "/DataPackProcessingFunctions/0");
  EXPECT_EQ(c.functions[1].file, dir_ / "tf.py");
  EXPECT_FALSE(c.functions[1].active);
  ASSERT_TRUE(c.status_function.has_value());
  EXPECT_EQ(c.status_function->file, dir_ / "tf.py");
  EXPECT_EQ(c.json["DataPackProcessingFunctions"][0]["FileName"], (dir_ / "tfs/tf.py").string());
  EXPECT_EQ(c.json["DataPackProcessingFunctions"][0]["IsActive"], true);
}

TEST_F(ConfigTest, EnvParamsMustBeKeyValue) {
  json doc = minimal();
  doc["EngineConfigs"][0]["EngineEnvParams"] = {"A=1", "NOVALUE"};
  EXPECT_EQ(error(doc),
            prefix() + "/EngineConfigs/0/EngineEnvParams/1: must be KEY=VALUE, got \"NOVALUE\"");
}

TEST_F(ConfigTest, FallsBackToSourceSchema) {
  fs::remove_all(share_ / "schemas");
  EXPECT_EQ(load(minimal()).engines[0].timestep_ns, 10'000'000);
}

// The build's own share dir: the simulation schema and python_json's schema are installed.
TEST_F(ConfigTest, BuildShareDir) {
  write(file(), minimal().dump());
  const SimulationConfig c = load_simulation_config(file(), {}, CONVOY_TEST_SHARE_DIR);
  EXPECT_EQ(c.engines[0].type, "python_json");
}

TEST_F(ConfigTest, GraphAndEventLoopKeys) {
  json doc = minimal();
  const SimulationConfig plain = load(doc);
  EXPECT_TRUE(plain.computational_graph.empty());
  EXPECT_FALSE(plain.mqtt_node || plain.ros_node);
  EXPECT_TRUE(plain.external_processes.empty());
  doc["DataPackProcessor"] = "cg";
  doc["ComputationalGraph"] = {"g1.py", "/abs/g2.py"};
  doc["EventLoop"] = {{"ExecutionMode", "OutputDriven"}};
  doc["MQTTNode"] = json::object();
  doc["ROSNode"] = {{"NodeName", "n"}};
  doc["DataPackProcessingFunctions"] = {{{"Name", "tf"}, {"FileName", "tf.py"}}};
  const SimulationConfig c = load(doc);
  EXPECT_EQ(c.computational_graph, (std::vector<fs::path>{dir_ / "g1.py", "/abs/g2.py"}));
  EXPECT_EQ(c.event_loop.execution_mode, "OutputDriven");
  EXPECT_DOUBLE_EQ(c.event_loop.timestep_s, 0.01);
  EXPECT_DOUBLE_EQ(c.event_loop.timestep_warn_threshold_s, 0.001);
  ASSERT_TRUE(c.mqtt_node && c.ros_node);
  EXPECT_EQ(c.mqtt_node->broker, "localhost:1883");
  EXPECT_EQ(c.mqtt_node->client_name, "NRP-core-client");
  EXPECT_EQ(c.ros_node->node_name, "n");
  EXPECT_EQ(c.warnings,
            (std::vector<std::string>{
                prefix() + "/DataPackProcessingFunctions: ignored: DataPackProcessor is cg "
                           "(as in NRP-Core, the graph replaces the transceiver functions)",
                prefix() + "/EventLoop: ignored: used with SimulationLoop EventLoop only"}));
  doc["EventLoop"] = {{"Timestep", 0}, {"ExecutionMode", "Sometimes"}};
  EXPECT_TRUE(Contains(error(doc), "/EventLoop/Timestep: must be > 0, got 0"));
  EXPECT_TRUE(Contains(error(doc), "/EventLoop/ExecutionMode: must be one of"));
}

TEST_F(ConfigTest, ExternalProcesses) {
  json doc = minimal();
  doc["ExternalProcesses"] = {
      {{"ProcCmd", "roslaunch x.launch"}, {"ProcStartParams", {"a"}}, {"ProcEnvParams", {"K=$V"}}},
      {{"ProcCmd", "y"}, {"LaunchCommand", {{"LaunchType", "EmptyLaunchCommand"}}}}};
  const SimulationConfig c = load(doc);
  ASSERT_EQ(c.external_processes.size(), 2u);
  EXPECT_EQ(c.external_processes[0].cmd, "roslaunch x.launch");
  EXPECT_EQ(c.external_processes[0].start_params, (std::vector<std::string>{"a"}));
  EXPECT_EQ(c.external_processes[0].env_params, (std::vector<std::string>{"K=$V"}));
  EXPECT_EQ(c.external_processes[0].launch_type, "BasicFork");
  EXPECT_EQ(c.external_processes[1].launch_type, "EmptyLaunchCommand");
  EXPECT_EQ(c.external_processes[1].pointer, "/ExternalProcesses/1");
  doc["ExternalProcesses"] = {{{"ProcCmd", "  "}, {"ProcEnvParams", {"=x"}}}, {{"ProcArgs", "a"}}};
  const std::string e = error(doc);
  EXPECT_TRUE(Contains(e, "/ExternalProcesses/1/ProcCmd: is required")) << e;
  doc["ExternalProcesses"].erase(1);
  EXPECT_EQ(error(doc), prefix() + "/ExternalProcesses/0/ProcCmd: is blank\n" + prefix() +
                            "/ExternalProcesses/0/ProcEnvParams/0: must be KEY=VALUE, got \"=x\"");
}

}  // namespace
}  // namespace convoy::config
