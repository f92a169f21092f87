/// @file loss_model.cpp
/// @brief Loss models (see loss_model.hpp).
#include "oneshot/engine/loss_model.hpp"

#include <sstream>

#include "oneshot/engine/json_fields.hpp"

namespace oneshot::engine {

double LossModel::loss_rate() const {
  switch (kind) {
    case Kind::kNone:
      return 0;
    case Kind::kBernoulli:
      return p;
    case Kind::kGilbertElliott: {
      const double pi_bad = p + r > 0 ? p / (p + r) : 0;  // π_B = p/(p + r)
      return (1 - pi_bad) * loss_good + pi_bad * loss_bad;
    }
  }
  return 0;
}

std::string LossModel::describe() const {
  std::ostringstream o;
  switch (kind) {
    case Kind::kNone:
      o << "none";
      break;
    case Kind::kBernoulli:
      o << "Bernoulli " << p;
      break;
    case Kind::kGilbertElliott:
      o << "Gilbert-Elliott p=" << p << " r=" << r << " k=" << loss_good << " h=" << loss_bad << " (rate "
        << loss_rate() << ")";
      break;
  }
  return o.str();
}

LossProcess::LossProcess(const LossModel& model, RandomStream rng) : model_(model), rng_(std::move(rng)) {}

bool LossProcess::next_lost() {
  switch (model_.kind) {
    case LossModel::Kind::kNone:
      return false;
    case LossModel::Kind::kBernoulli:
      return rng_.bernoulli(model_.p);
    case LossModel::Kind::kGilbertElliott: {
      if (!started_) {  // start in the stationary law
        const double pi_bad = model_.p + model_.r > 0 ? model_.p / (model_.p + model_.r) : 0;
        bad_ = rng_.bernoulli(pi_bad);
        started_ = true;
      }
      const bool lost = rng_.bernoulli(bad_ ? model_.loss_bad : model_.loss_good);
      const double u = rng_.uniform01();
      bad_ = bad_ ? !(u < model_.r) : u < model_.p;
      return lost;
    }
  }
  return false;
}

LossModel parse_loss_model(const nlohmann::json& j, const std::string& field) {
  if (!j.is_object()) throw InputError("field '" + field + "': must be an object");
  const std::string model = string_of(j, field, "model");
  LossModel l;
  if (model == "none") {
    require_keys(j, field, {"model"});
  } else if (model == "bernoulli") {
    require_keys(j, field, {"model", "p"});
    l.kind = LossModel::Kind::kBernoulli;
    l.p = number_in(j, field, "p", 0, 1);
  } else if (model == "gilbert_elliott") {
    require_keys(j, field, {"model", "p_good_to_bad", "p_bad_to_good", "loss_good", "loss_bad"});
    l.kind = LossModel::Kind::kGilbertElliott;
    l.p = number_in(j, field, "p_good_to_bad", 0, 1);
    l.r = number_in(j, field, "p_bad_to_good", 0, 1);
    l.loss_good = number_in(j, field, "loss_good", 0, 1, true, 0);
    l.loss_bad = number_in(j, field, "loss_bad", 0, 1, true, 1);
    if (l.p + l.r <= 0) throw InputError("field '" + field + "': p_good_to_bad + p_bad_to_good must be positive");
  } else {
    throw InputError("field '" + field + ".model': unknown loss model '" + model + "' (none, bernoulli, gilbert_elliott)");
  }
  return l;
}

}  // namespace oneshot::engine
