#include "transport/grpc_security.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace convoy::transport {

std::string read_pem(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(std::string(what) + " '" + path + "' cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  if (s.str().find("-----BEGIN") == std::string::npos)
    throw std::invalid_argument(std::string(what) + " '" + path + "' is not a PEM file");
  return s.str();
}

std::shared_ptr<grpc::ChannelCredentials> channel_credentials(const ClientSecurity& s) {
  if (!s.tls) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions o;
  if (!s.ca_file.empty()) o.pem_root_certs = read_pem(s.ca_file, "ServerTLS/CACertificate");
  if (!s.cert_file.empty() || !s.key_file.empty()) {
    if (s.cert_file.empty() || s.key_file.empty())
      throw std::invalid_argument("ServerTLS: ClientCertificate and ClientKey go together");
    o.pem_cert_chain = read_pem(s.cert_file, "ServerTLS/ClientCertificate");
    o.pem_private_key = read_pem(s.key_file, "ServerTLS/ClientKey");
  }
  return grpc::SslCredentials(o);
}

std::shared_ptr<grpc::ServerCredentials> server_credentials(const ServerSecurity& s) {
  if (s.cert_file.empty() && s.key_file.empty()) {
    if (!s.client_ca_file.empty())
      throw std::invalid_argument("--tls-client-ca needs --tls-cert and --tls-key");
    return grpc::InsecureServerCredentials();
  }
  if (s.cert_file.empty() || s.key_file.empty())
    throw std::invalid_argument("--tls-cert and --tls-key go together");
  grpc::SslServerCredentialsOptions o(
      s.client_ca_file.empty() ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                               : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  o.pem_key_cert_pairs.push_back(
      {read_pem(s.key_file, "--tls-key"), read_pem(s.cert_file, "--tls-cert")});
  if (!s.client_ca_file.empty()) o.pem_root_certs = read_pem(s.client_ca_file, "--tls-client-ca");
  return grpc::SslServerCredentials(o);
}

bool is_loopback_address(const std::string& address) {
  if (address.rfind("unix:", 0) == 0 || address.rfind("unix-abstract:", 0) == 0) return true;
  std::string host = address;
  if (host.rfind("ipv4:", 0) == 0) host = host.substr(5);
  if (host.rfind("ipv6:", 0) == 0) host = host.substr(5);
  if (!host.empty() && host.front() == '[') {
    const auto end = host.find(']');
    return end != std::string::npos && host.substr(1, end - 1) == "::1";
  }
  const auto colon = host.rfind(':');
  if (colon != std::string::npos) host = host.substr(0, colon);
  return host == "localhost" || host.rfind("127.", 0) == 0;
}

void check_listening_policy(const std::string& address, const ServerSecurity& s) {
  if (is_loopback_address(address) || s.insecure) return;
  if (!s.cert_file.empty() || !s.token.empty()) return;
  throw std::invalid_argument(
      "refusing to listen at " + address +
      " without TLS or a token: anyone who reaches it could step the simulation and feed it "
      "datapacks. Give --tls-cert/--tls-key and/or a token (" +
      kTokenEnv + " or --token-file), listen on localhost, or say --insecure");
}

bool same_token(std::string_view expected, std::string_view given) {
  if (expected.empty()) return false;
  unsigned char diff = expected.size() == given.size() ? 0 : 1;
  for (size_t i = 0; i < given.size(); ++i)
    diff |= static_cast<unsigned char>(given[i] ^ expected[i % expected.size()]);
  return diff == 0;
}

}  // namespace convoy::transport
