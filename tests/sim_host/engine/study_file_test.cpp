/// @file study_file_test.cpp
/// @brief The study file: the documented example parses to what it says, a study's
///        schema is enforced, every malformed input is refused with its field named, an inline
///        plant with the design keys is the plant-file description of its matrices, and a
///        file with several loops (loops[]) gives each its plant and nodes.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <set>
#include <utility>
#include <sstream>

#include "oneshot/design/plant_description.hpp"
#include "oneshot/engine/study_file.hpp"
#include "support/expect_error.hpp"

namespace oneshot::engine {
namespace {

std::string example_text() {
  std::ifstream in(std::string(ONESHOT_SOURCE_DIR) + "/sim_host/engine/examples/example_study.json");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

StudySchema example_schema() {
  StudySchema s;
  s.study = "example";
  s.approach_kinds = {"ideal", "kalman"};
  s.approach_params = {{"process_noise_scale", 0, 100, false, false, 1}};
  s.scenario_params = {{"amplitude", 0, 1.65, false, true, 0}, {"period_s", 0.1, 100, false, false, 2}};
  return s;
}

TEST(StudyFile, TheDocumentedExampleParses) {
  const StudySchema schema = example_schema();
  const StudyFile f = parse_study(example_text(), "example_study.json", &schema);
  EXPECT_EQ(f.study, "example");
  ASSERT_EQ(f.plant.kind, PlantSpec::Kind::kContinuous);
  EXPECT_EQ(f.plant.continuous.a(0, 1), -23.8);
  EXPECT_EQ(f.seeds, 50U);
  ASSERT_EQ(f.nodes.size(), 3U);
  EXPECT_EQ(f.node("sensor").period, from_us(50000));
  ASSERT_TRUE(f.node("sensor").trigger.has_value());
  EXPECT_EQ(f.node("sensor").trigger->time_steps, 10U);
  EXPECT_EQ(f.node("controller").clock_offset, from_us(120));
  ASSERT_EQ(f.links.size(), 2U);
  EXPECT_EQ(f.links[1].bus, "can0");
  EXPECT_EQ(f.buses[0].background[0].deadline, from_us(5000));  // deadline defaults to the period
  EXPECT_EQ(f.approaches[0].params.at("process_noise_scale"), 1.0);  // schema default
  EXPECT_EQ(f.scenarios[0].params.at("period_s"), 2.0);
  const LinkConfig base = f.link_config("sc");
  const LinkConfig heavy = f.link_config("sc", &f.scenarios[1]);
  EXPECT_EQ(base.delay.kind, DelayModel::Kind::kUniform);
  EXPECT_EQ(heavy.delay.kind, DelayModel::Kind::kLognormal);
  EXPECT_EQ(heavy.loss.kind, LossModel::Kind::kBernoulli);
  EXPECT_EQ(*f.scenarios[1].duration_s, 10.0);
  // Without a schema any kind and finite parameter passes.
  EXPECT_NO_THROW(parse_study(example_text(), "x", nullptr));
}

/// The example with `from` replaced by `to` (must occur).
std::string edited(const std::string& from, const std::string& to) {
  std::string s = example_text();
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(StudyFile, AWordParameterIsOneOfItsWordsAndNeverANumber) {
  StudySchema schema = example_schema();
  schema.approach_params.push_back({"rule", 0, 0, false, false, 0, {"fast", "slow"}});
  const auto parse = [&](const std::string& to, const StudySchema* sc) {
    return parse_study(edited("{\"process_noise_scale\": 1}", to), "x", sc);
  };
  const StudyFile f = parse("{\"process_noise_scale\": 1, \"rule\": \"slow\"}", &schema);
  EXPECT_EQ(f.approaches[1].words.at("rule"), "slow");
  EXPECT_EQ(f.approaches[1].params.count("rule"), 0U);          // not among the numbers
  EXPECT_EQ(f.approaches[0].words.count("rule"), 0U);           // absent: not filled in (the study decides)
  EXPECT_EQ(parse("{}", &schema).approaches[1].params.at("process_noise_scale"), 1.0);  // numbers still defaulted
  const auto refused = [&](const std::string& to, const std::string& expect) {
    try {
      static_cast<void>(parse(to, &schema));
      ADD_FAILURE() << to << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  };
  refused("{\"rule\": \"medium\"}", "field 'approaches[1].params.rule': must be one of fast, slow");
  refused("{\"rule\": 1}", "field 'approaches[1].params.rule': must be one of fast, slow (a string)");
  refused("{\"process_noise_scale\": \"one\"}", "field 'approaches[1].params.process_noise_scale': must be a finite number");
  refused("{\"speed\": \"fast\"}", "field 'approaches[1].params.speed': unknown parameter");
  // Without a schema any word passes, kept for the study's mapping.
  EXPECT_EQ(parse("{\"rule\": \"any\"}", nullptr).approaches[1].words.at("rule"), "any");
}

TEST(StudyFile, AnInlinePlantWithDesignKeysIsThePlantFilesDescription) {
  const StudyFile bare = parse_study(example_text(), "example_study.json", nullptr);
  EXPECT_EQ(bare.plant.design, nullptr);  // no design keys: not designed
  const StudyFile f = parse_study(
      edited("\"Q1c\"", "\"period_us\": 50000, \"measurement_covariance\": [[8e-5, 0], [0, 8e-5]], \"outputs\": [\"v1\", \"v2\"], "
                         "\"tracked_outputs\": [\"v1\"], \"actuator\": {\"u_min\": [-1.65], \"u_max\": [1.65]}, \"Q1c\""),
      "example_study.json", nullptr);
  ASSERT_NE(f.plant.design, nullptr);
  const design::PlantDescription& d = *f.plant.design;
  EXPECT_TRUE(d.continuous());
  EXPECT_EQ(d.period_us, 50000);
  EXPECT_EQ(d.name, "inline");
  EXPECT_EQ(d.a.values, f.plant.continuous.a.values);
  EXPECT_EQ(d.b.values, f.plant.continuous.b.values);
  EXPECT_EQ(d.c.values, f.plant.continuous.c.values);
  EXPECT_EQ(d.process_intensity.values, f.plant.continuous.qc.values);
  EXPECT_EQ(d.q1c.values, f.plant.continuous.q1c.values);
  EXPECT_EQ(d.q2c.values, f.plant.continuous.q2c.values);
  EXPECT_EQ(d.measurement_covariance(1, 1), 8e-5);
  ASSERT_EQ(d.tracked_outputs.size(), 1U);
  EXPECT_EQ(d.tracked_outputs[0], 0U);
  EXPECT_TRUE(d.has_actuator_range);
  EXPECT_EQ(d.u_max[0], 1.65);
}

TEST(StudyFile, MalformedFilesNameTheField) {
  const StudySchema schema = example_schema();
  struct Case {
    std::string text;
    const char* expected;
  };
  const Case cases[] = {
      {edited("\"duration_s\": 20,", "\"duration_s\": 20, \"duration_s\": 30,"), "duplicate key 'duration_s'"},
      {edited("\"duration_s\": 20,", "\"duratoin_s\": 20,"), "study file.duratoin_s"},
      {edited("\"duration_s\": 20,", "\"duration_s\": -1,"), "duration_s"},
      {edited("\"count\": 50", "\"count\": 1"), "seeds.count"},
      {edited("oneshot-study/1", "oneshot-study/2"), "schema"},
      {edited("\"study\": \"example\"", "\"study\": \"ncs\""), "study"},
      {edited("\"A\": [[0, -23.8], [0, 0]]", "\"A\": [[0, -23.8], [0]]"), "plant.continuous.A"},
      {edited("\"C\": [[1, 0], [0, 1]]", "\"C\": [[1, 0, 0]]"), "plant.continuous.C"},
      {edited("\"Q_c\": [[4e-6, 0], [0, 4e-6]]", "\"Q_c\": [[4e-6, 1], [1, 4e-6]]"), "plant.continuous.Q_c"},
      {edited("\"Q_c\": [[4e-6, 0], [0, 4e-6]]", "\"Q_c\": [[4e-6, 0], [1, 4e-6]]"), "not symmetric"},
      {edited("\"Q1c\"", "\"measurement_covariance\": [[1, 0], [0, 1]], \"Q1c\""), "plant.continuous.period_us': missing"},
      {edited("\"Q1c\"", "\"period_us\": 0, \"measurement_covariance\": [[1, 0], [0, 1]], \"Q1c\""), "plant.continuous.period_us"},
      {edited("\"Q1c\"", "\"period_us\": 1000, \"measurement_covariance\": [[1, 1], [0, 1]], \"Q1c\""),
       "plant.continuous.measurement_covariance': not symmetric"},
      {edited("\"Q1c\"", "\"period_us\": 1000, \"measurement_covariance\": [[1, 0], [0, 0]], \"Q1c\""),
       "plant.continuous.measurement_covariance': must be positive definite"},
      {edited("\"Q1c\"", "\"period_us\": 1000, \"measurement_covariance\": [[1, 0], [0, 1]], \"tracked_outputs\": [\"z\"], \"Q1c\""),
       "plant.continuous.tracked_outputs[0]"},
      {edited("\"address\": 2", "\"address\": 1"), "nodes[1].address"},
      {edited("\"address\": 3", "\"address\": 300"), "nodes[2].address"},
      {edited("\"role\": \"actuator\"", "\"role\": \"relay\""), "nodes[2].role"},
      {edited("\"mode\": \"arrival\", \"clock_offset_us\"", "\"mode\": \"arrival\", \"period_us\": 5, \"clock_offset_us\""),
       "nodes[1].period_us"},
      {edited("\"time_steps\": 10", "\"time_steps\": -10"), "nodes[0].trigger.time_steps"},
      {edited("\"rule\": \"send_on_delta\"", "\"rule\": \"sometimes\""), "nodes[0].trigger.rule"},
      {edited("\"to\": \"controller\"", "\"to\": \"plant\""), "no node 'plant'"},
      {edited("\"max_us\": 4000", "\"max_us\": 400"), "links[0].delay.max_us"},
      {edited("\"p_bad_to_good\": 0.3", "\"p_bad_to_good\": 1.3"), "links[0].loss.p_bad_to_good"},
      {edited("\"order\": \"any\"", "\"order\": \"lifo\""), "links[0].order"},
      {edited("\"bus\": \"can0\", \"id\": 16", "\"bus\": \"can0\", \"id\": 256"), "links[1].id"},
      {edited("\"bus\": \"can0\", \"id\": 16", "\"bus\": \"can1\", \"id\": 16"), "links[1].bus"},
      {edited("\"bit_rate\": 500000", "\"bit_rate\": 300000"), "buses[0].bit_rate"},
      {edited("\"kind\": \"kalman\"", "\"kind\": \"magic\""), "approaches[1].kind"},
      {edited("\"process_noise_scale\": 1", "\"process_noise_scale\": 1000"), "approaches[1].params.process_noise_scale"},
      {edited("{\"amplitude\": 0.2}", "{\"amplitude\": 0.2, \"gain\": 3}"), "scenarios[0].params.gain"},
      {edited("{\"amplitude\": 0.2}", "{}"), "scenarios[0].params.amplitude"},
      {edited("\"name\": \"d4\"", "\"name\": \"d14-heavy\""), "scenarios[1].name"},
      {edited("\"links\": {\"sc\"", "\"links\": {\"ca\""), "scenarios[1].links.ca': link 'ca' runs on CAN bus"},
      {edited("\"links\": {\"sc\"", "\"links\": {\"xy\""), "scenarios[1].links.xy': no link 'xy'"},
      {edited("\"sigma\": 0.6", "\"sigma\": \"wide\""), "scenarios[1].links.sc.delay.sigma"},
      {"{\"schema\": ", "not valid JSON"},
      // Found by fuzz_study: a number beyond double escaped as nlohmann's out_of_range.
      {edited("\"duration_s\": 20,", "\"duration_s\": 5001e308,"), "not valid JSON"},
      {"[]", "must be an object"},
      {std::string(40, '[') + std::string(40, ']'), "nested deeper than 32"},
  };
  for (const Case& c : cases) {
    try {
      parse_study(c.text, "f.json", &schema);
      ADD_FAILURE() << "accepted; expected an error naming " << c.expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("f.json", 0), 0U) << e.what();
    }
  }
}

TEST(StudyFile, SeveralLoopsEachHaveTheirPlantAndNodes) {
  const StudySchema schema = example_schema();
  nlohmann::json j = nlohmann::json::parse(example_text());
  const nlohmann::json plant = j.at("plant");
  j.erase("plant");
  j["loops"] = {{{"name", "one"}, {"plant", plant}, {"sensor", "sensor"}, {"controller", "controller"}, {"actuator", "actuator"}}};
  const StudyFile f = parse_study(j.dump(), "f.json", &schema);
  ASSERT_EQ(f.loops.size(), 1U);
  EXPECT_EQ(f.loops[0].plant.kind, PlantSpec::Kind::kContinuous);
  EXPECT_EQ(f.loops[0].plant.continuous.a(0, 1), -23.8);
  EXPECT_EQ(f.loops[0].controller, "controller");
  EXPECT_TRUE(f.plant.file.empty());  // the top-level plant is unset
  // Without loops: the one loop of the file, as before.
  EXPECT_TRUE(parse_study(example_text(), "f.json", &schema).loops.empty());
  struct Case {
    std::function<void(nlohmann::json&)> edit;
    const char* expected;
  };
  const Case cases[] = {
      {[&](nlohmann::json& x) { x["plant"] = plant; }, "field 'plant'"},
      {[](nlohmann::json& x) { x["loops"] = nlohmann::json::array(); }, "field 'loops'"},
      {[](nlohmann::json& x) { x["loops"][0]["period_us"] = 5; }, "field 'loops[0].period_us'"},
      {[](nlohmann::json& x) { x["loops"][0].erase("plant"); }, "field 'loops[0].plant'"},
      {[](nlohmann::json& x) { x["loops"][0]["plant"] = {{"file", 3}}; }, "loops[0].plant"},
      {[](nlohmann::json& x) { x["loops"][0]["name"] = "a/b"; }, "field 'loops[0].name'"},
      {[](nlohmann::json& x) { x["loops"][0]["sensor"] = "nobody"; }, "field 'loops[0].sensor'"},
      {[](nlohmann::json& x) { x["loops"][0]["actuator"] = "sensor"; }, "field 'loops[0].actuator'"},
      {[](nlohmann::json& x) { x["loops"].push_back(x["loops"][0]); }, "field 'loops[1].sensor'"},  // a node in two loops
      {[](nlohmann::json& x) {
         x["loops"].push_back(x["loops"][0]);
         x["nodes"].push_back({{"name", "s2"}, {"role", "sensor"}, {"address", 9}, {"period_us", 1000}});
         x["loops"][1]["sensor"] = "s2";
       },
       "field 'loops[1].controller'"},
      {[](nlohmann::json& x) { x["nodes"].push_back({{"name", "spare"}, {"role", "sensor"}, {"address", 9}, {"period_us", 1000}}); },
       "field 'nodes[3]'"},  // in no loop
  };
  for (const Case& c : cases) {
    nlohmann::json x = j;
    c.edit(x);
    try {
      parse_study(x.dump(), "f.json", &schema);
      ADD_FAILURE() << "accepted; expected an error naming " << c.expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
}

TEST(StudyFile, ReferencesParseStrictlyAtTheTopAndPerScenario) {
  const StudySchema schema = example_schema();
  const StudyFile f = parse_study(
      edited("\"scenarios\": [", "\"reference\": {\"kind\": \"steps\", \"steps\": [[0, 0.1], [1.5, -0.2]]}, \"scenarios\": ["),
      "f.json", &schema);
  ASSERT_TRUE(f.reference.has_value());
  EXPECT_EQ(f.reference->kind, ReferenceSpec::Kind::kSteps);
  ASSERT_EQ(f.reference->steps.size(), 2U);
  EXPECT_EQ(f.reference->steps[1], std::make_pair(1.5, -0.2));
  EXPECT_EQ(f.reference->field, "reference");
  EXPECT_EQ(f.reference->describe(), "steps (2)");
  EXPECT_EQ(f.scenarios[0].params_given, std::set<std::string>{"amplitude"});  // period_s: the schema's default
  const StudyFile g = parse_study(
      edited("{\"amplitude\": 0.2}", "{\"amplitude\": 0.2}, \"reference\": {\"kind\": \"square\", \"amplitude_volts\": 0.3, \"period_s\": 2}"),
      "f.json", &schema);
  ASSERT_TRUE(g.scenarios[0].reference.has_value());
  EXPECT_EQ(g.scenarios[0].reference->field, "scenarios[0].reference");
  EXPECT_EQ(g.scenarios[0].reference->amplitude_volts, 0.3);
  EXPECT_FALSE(g.reference.has_value());
  // The CSV form, line by line.
  const auto steps = parse_reference_csv("t_s,value_volts\r\n# c\n\n0, 1\n2.5,-1e-3\n", "reference.path", "x.csv");
  ASSERT_EQ(steps.size(), 2U);
  EXPECT_EQ(steps[1], std::make_pair(2.5, -1e-3));
  // A UTF-8 byte-order mark before the header (what spreadsheets write) is not part of it.
  EXPECT_EQ(parse_reference_csv("\xEF\xBB\xBFt_s,value_volts\n0,1\n", "reference.path", "x.csv").size(), 1U);
  const std::pair<const char*, const char*> bad[] = {
      {"", "x.csv line 1"},
      {"t_s;value_volts\n0,1\n", "x.csv line 1"},
      {"t_s,value_volts\n0,1\n0,2\n", "x.csv line 3: times must increase strictly"},
      {"t_s,value_volts\n0,inf\n", "x.csv line 2: expected two finite numbers"},
      {"t_s,value_volts\n1e400,0\n", "x.csv line 2: expected two finite numbers"},
      {"t_s,value_volts\n0\n", "x.csv line 2"},
      {"t_s,value_volts\n2e6,0\n", "x.csv line 2: t_s must be finite in [0, 1e6] s"},
      {"t_s,value_volts\n", "x.csv: no steps"},
  };
  for (const auto& [text, expect] : bad) {
    try {
      static_cast<void>(parse_reference_csv(text, "reference.path", "x.csv"));
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("field 'reference.path': ") + expect), std::string::npos) << e.what();
    }
  }
}

TEST(StudyFile, DiscretePlantsAndDimensionLimits) {
  const std::string discrete = edited(
      R"("continuous": {
      "A": [[0, -23.8], [0, 0]],
      "B": [[0], [-23.8]],
      "C": [[1, 0], [0, 1]],
      "Q_c": [[4e-6, 0], [0, 4e-6]],
      "Q1c": [[1, 0], [0, 1]],
      "Q2c": [[1]]
    })",
      R"("discrete": {"Phi": [[1.25, 1, 0], [0, 0.9, 7], [0, 0, 0.6]], "Gamma": [[2.2], [1], [0.1]],
                   "C": [[1, 0, 2]], "Q": [[20, 0, 0], [0, 20, 0], [0, 0, 20]], "period_us": 10000})");
  const StudyFile f = parse_study(discrete, "d.json", nullptr);
  ASSERT_EQ(f.plant.kind, PlantSpec::Kind::kDiscrete);
  EXPECT_EQ(f.plant.discrete.period, from_us(10000));
  const auto cfg = make_discrete_config<3, 1, 1, 1>(f.plant.discrete, "dropping");
  EXPECT_EQ(cfg.phi(0, 0), 1.25);
  EXPECT_THROW((make_discrete_config<2, 1, 1, 1>(f.plant.discrete, "dropping")), std::invalid_argument);
  std::ostringstream a;
  a << "[";
  for (int i = 0; i < 17; ++i) {
    a << (i ? "," : "") << "[";
    for (int j = 0; j < 17; ++j) a << (j ? "," : "") << 0;
    a << "]";
  }
  a << "]";
  std::ostringstream b;
  b << "[";
  for (int i = 0; i < 17; ++i) b << (i ? "," : "") << "[1]";
  b << "]";
  std::ostringstream c;
  c << "[[";
  for (int j = 0; j < 17; ++j) c << (j ? "," : "") << 1;
  c << "]]";
  const std::string huge = edited(R"("A": [[0, -23.8], [0, 0]],
      "B": [[0], [-23.8]],
      "C": [[1, 0], [0, 1]],
      "Q_c": [[4e-6, 0], [0, 4e-6]],)",
                                  "\"A\": " + a.str() + ", \"B\": " + b.str() + ", \"C\": " + c.str() + ", \"Q_c\": " + a.str() + ",");
  test::expect_error_naming<InputError>([&] { parse_study(huge, "h.json", nullptr); }, {"kMaxStates"});
}

}  // namespace
}  // namespace oneshot::engine
