#include "service/json_config.hpp"

#include "core/error.hpp"

namespace levelset::service {

using nlohmann::json;

namespace {

constexpr int kMaxDepth = 16;
constexpr std::size_t kMaxTuple = 65536;

void fill_set(config::Set& set, const json& object, const std::string& path, int depth);

config::Entry make_entry(const std::string& key, const json& v, const std::string& path, int depth) {
  config::Entry e;
  e.key = key;
  e.override_text = path;
  if (depth > kMaxDepth) throw Error(ErrorCode::LimitExceeded, path, "nested deeper than " + std::to_string(kMaxDepth));
  if (v.is_object()) {
    e.is_set = true;
    fill_set(e.set, v, path, depth + 1);
  } else if (v.is_number()) {
    e.value.kind = config::Value::Kind::Number;
    e.value.number = v.get<double>();
    e.value.text = v.dump();
  } else if (v.is_string()) {
    e.value.kind = config::Value::Kind::String;
    e.value.text = v.get<std::string>();
  } else if (v.is_boolean()) {
    e.value.kind = config::Value::Kind::Word;
    e.value.text = v.get<bool>() ? "yes" : "no";
  } else if (v.is_array()) {
    e.value.kind = config::Value::Kind::Tuple;
    for (const json& item : v) {
      if (item.is_number()) {
        e.value.tuple.push_back(item.get<double>());
      } else if (item.is_array()) {
        for (const json& x : item) {
          if (!x.is_number()) throw Error(ErrorCode::InvalidArgument, path, "expected numbers or arrays of numbers");
          e.value.tuple.push_back(x.get<double>());
        }
      } else {
        throw Error(ErrorCode::InvalidArgument, path, "expected numbers or arrays of numbers");
      }
      if (e.value.tuple.size() > kMaxTuple) throw Error(ErrorCode::LimitExceeded, path, "more than 65536 numbers");
    }
    e.value.text = v.dump();
  } else {
    throw Error(ErrorCode::InvalidArgument, path, "null is not a value");
  }
  return e;
}

void fill_set(config::Set& set, const json& object, const std::string& path, int depth) {
  if (!object.is_object()) throw Error(ErrorCode::InvalidArgument, path, "expected an object");
  if (object.size() > 4096) throw Error(ErrorCode::LimitExceeded, path, "more than 4096 keys");
  for (const auto& [key, value] : object.items()) set.entries.push_back(make_entry(key, value, path + "." + key, depth));
}

}  // namespace

config::Set json_to_config(const json& object, const std::string& path) {
  config::Set set;
  fill_set(set, object, path, 0);
  return set;
}

void add_entry(config::Set& set, const std::string& key, const json& value, const std::string& path) {
  set.entries.push_back(make_entry(key, value, path, 0));
}

void add_word(config::Set& set, const std::string& key, const std::string& word) {
  config::Entry e;
  e.key = key;
  e.value.kind = config::Value::Kind::Word;
  e.value.text = word;
  set.entries.push_back(std::move(e));
}

}  // namespace levelset::service
