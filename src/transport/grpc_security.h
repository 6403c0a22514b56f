// Who may talk to a remote engine: TLS and a shared token for the gRPC transport.
//
// An engine server reached over TCP (EmptyLaunchCommand) can be stepped and fed datapacks by
// anyone who reaches its port. So an engine server listens on another address than the
// loopback only with TLS (a server certificate, and optionally client certificates) or a
// shared token, unless told --insecure. Localhost stays plain by default: NRP-Core's own
// clients use insecure channels. The token travels as call metadata (kTokenMetadataKey); it
// is never logged.
#pragma once

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>
#include <string_view>

namespace convoy::transport {

inline constexpr const char* kTokenMetadataKey = "x-convoy-token";
// The environment variable both sides read the token from when none is given otherwise.
inline constexpr const char* kTokenEnv = "CONVOY_ENGINE_TOKEN";

// The coordinator's side (an engine's ServerTLS / AuthToken keys).
struct ClientSecurity {
  bool tls = false;
  std::string ca_file;      // PEM roots that sign the server's certificate ("": system roots)
  std::string cert_file;    // PEM client certificate, for servers that ask for one
  std::string key_file;     // its private key
  std::string server_name;  // name to check the certificate against ("": the address' host)
  std::string token;        // "" for none
};

// The engine server's side (its command line).
struct ServerSecurity {
  std::string cert_file, key_file;  // PEM server certificate and key: TLS when set
  std::string client_ca_file;       // PEM roots: clients must present a certificate they sign
  std::string token;                // "" for none
  bool insecure = false;            // --insecure: plain on any address, with a warning
};

std::shared_ptr<grpc::ChannelCredentials> channel_credentials(const ClientSecurity& s);
std::shared_ptr<grpc::ServerCredentials> server_credentials(const ServerSecurity& s);

// Whether a gRPC listening address reaches this machine only: "localhost:P", "127.x.y.z:P",
// "[::1]:P", "unix:...".
bool is_loopback_address(const std::string& address);

// Throws std::invalid_argument explaining why the server may not listen at `address` with
// `s` (another address than the loopback, without TLS or token, and not --insecure).
void check_listening_policy(const std::string& address, const ServerSecurity& s);

// Compares two tokens in time that does not depend on where they differ.
bool same_token(std::string_view expected, std::string_view given);

// The whole content of a PEM file; throws std::invalid_argument naming it.
std::string read_pem(const std::string& path, const char* what);

}  // namespace convoy::transport
