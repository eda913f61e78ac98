#include "api/replica_routing.hpp"

#include "core/error.hpp"
#include "service/ids.hpp"

namespace levelset::api {

using nlohmann::json;

ReplicaRouting::ReplicaRouting(std::string self, const std::string& peers) : self_(std::move(self)) {
  for (std::size_t start = 0; start < peers.size();) {
    const std::size_t end = std::min(peers.find(',', start), peers.size());
    const std::string item = peers.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || item.compare(eq + 1, 4, "http") != 0)
      throw Error(ErrorCode::InvalidArgument, "peers", "expected REPLICA=http://HOST:PORT, found '" + item.substr(0, 80) + "'");
    std::string url = item.substr(eq + 1);
    while (!url.empty() && url.back() == '/') url.pop_back();
    const std::string name = item.substr(0, eq);
    if (name != self_) peers_[name] = url;
  }
}

std::optional<std::string> ReplicaRouting::redirect_for(const std::string& id, const std::string& target) const {
  const std::string replica = service::replica_of(id);
  if (replica.empty() || replica == self_) return std::nullopt;
  const auto it = peers_.find(replica);
  if (it == peers_.end()) return std::nullopt;
  return it->second + target;
}

json ReplicaRouting::peer_sessions(const std::string& authorization, json& unreachable) const {
  json all = json::array();
  unreachable = json::array();
  for (const auto& [name, url] : peers_) {
    httplib::Client client(url);
    client.set_connection_timeout(2);
    client.set_read_timeout(5);
    httplib::Headers headers;
    if (!authorization.empty()) headers.emplace("Authorization", authorization);
    const httplib::Result r = client.Get("/api/v1/sessions?local=1", headers);
    json body = r && r->status == 200 ? json::parse(r->body, nullptr, false) : json();
    if (!body.is_object() || !body.contains("sessions") || !body["sessions"].is_array()) {
      unreachable.push_back(name);
      continue;
    }
    for (json& s : body["sessions"]) {
      s["replica"] = name;
      all.push_back(std::move(s));
    }
  }
  return all;
}

}  // namespace levelset::api
