// JSON request bodies as config trees, so the daemon's operations reuse the job files'
// mapping (jobs/), keys, ranges and messages. Numbers -> Number, strings -> String (formulas
// keep their text), booleans -> yes / no, arrays of numbers (or of number triples) -> one
// Tuple, objects -> sets. Every entry records its field path ("body.evolve.speed"), which
// config::place_of reports in errors. Limits: depth 16, 4096 entries, 65536 tuple numbers.
// Errors: Error{InvalidArgument} at the field for null or mixed arrays.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "config/config_file.hpp"

namespace levelset::service {

config::Set json_to_config(const nlohmann::json& object, const std::string& path = "body");
void add_entry(config::Set& set, const std::string& key, const nlohmann::json& value, const std::string& path);
void add_word(config::Set& set, const std::string& key, const std::string& word);

}  // namespace levelset::service
