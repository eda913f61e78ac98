// Session-affine routing across replicas. Every session and job id starts with the name of the
// replica that holds it (service/ids.hpp); with `peers` configured (REPLICA=URL,...), a request
// naming another replica's session or job is answered with a 307 redirect to that replica, and
// GET /api/v1/sessions merges every replica's list (each peer asked with ?local=1). Kubernetes
// gives each pod of the StatefulSet a stable name and DNS entry, so the peer list is static.
// Threading: const after construction; peer requests use a client per call.
#pragma once

#include <map>
#include <optional>
#include <string>

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace levelset::api {

class ReplicaRouting {
 public:
  ReplicaRouting(std::string self, const std::string& peers);  // Error{InvalidArgument} on a malformed list

  bool enabled() const { return !peers_.empty(); }
  // The URL to redirect to when `id` belongs to a known peer; nullopt when it is ours or unknown.
  std::optional<std::string> redirect_for(const std::string& id, const std::string& target) const;
  // Every peer's sessions (their "sessions" arrays), and the peers that did not answer.
  nlohmann::json peer_sessions(const std::string& authorization, nlohmann::json& unreachable) const;

 private:
  std::string self_;
  std::map<std::string, std::string> peers_;  // replica -> base URL
};

}  // namespace levelset::api
