// Credentials set-up without a network: option checks, files that are
// missing or empty named in the error, the constant-time comparison. The
// handshakes and token checks over real connections are in
// tests/security_test.cc (they need a CA made with openssl).
#include "common/rpc/credentials.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace meshseek::rpc {
namespace {

using ::testing::HasSubstr;

std::string WriteFile(const std::string& name, const std::string& contents) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << contents;
  return path;
}

TEST(CredentialsTest, DefaultsArePlaintextAndValid) {
  EXPECT_TRUE(ServerSecurityOptions().Validate().ok());
  EXPECT_TRUE(ClientSecurityOptions().Validate().ok());
  EXPECT_FALSE(ServerSecurityOptions().tls_enabled());
  EXPECT_FALSE(ClientSecurityOptions().tls_enabled());
  EXPECT_TRUE(MakeServerCredentials({}).ok());
  EXPECT_TRUE(MakeChannelCredentials({}).ok());
}

TEST(CredentialsTest, CertificateAndKeyGoTogether) {
  ServerSecurityOptions server;
  server.tls.cert_file = "/a.pem";
  EXPECT_THAT(std::string(server.Validate().message()), HasSubstr("--tls_key"));
  ClientSecurityOptions client;
  client.tls.key_file = "/a.key";
  EXPECT_THAT(std::string(client.Validate().message()), HasSubstr("--tls_cert"));
}

TEST(CredentialsTest, TokenNeedsTls) {
  ServerSecurityOptions server;
  server.token_file = "/token";
  EXPECT_EQ(server.Validate().code(), absl::StatusCode::kInvalidArgument);
  ClientSecurityOptions client;
  client.token_file = "/token";
  EXPECT_EQ(client.Validate().code(), absl::StatusCode::kInvalidArgument);
  client.tls.ca_file = "/ca.pem";
  EXPECT_TRUE(client.Validate().ok());
}

TEST(CredentialsTest, MissingFileIsNamed) {
  ServerSecurityOptions server;
  server.tls.cert_file = "/nonexistent/meshseek/cert.pem";
  server.tls.key_file = "/nonexistent/meshseek/key.pem";
  auto credentials = MakeServerCredentials(server);
  ASSERT_FALSE(credentials.ok());
  EXPECT_EQ(credentials.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(credentials.status().message()),
              HasSubstr("--tls_cert '/nonexistent/meshseek/cert.pem'"));
  ClientSecurityOptions client;
  client.tls.ca_file = "/nonexistent/meshseek/ca.pem";
  EXPECT_THAT(std::string(MakeChannelCredentials(client).status().message()),
              HasSubstr("--tls_ca '/nonexistent/meshseek/ca.pem'"));
}

TEST(CredentialsTest, EmptyOrBlankFilesAreRefused) {
  EXPECT_EQ(ReadSecretFile(WriteFile("meshseek_empty", ""), "--tls_ca").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(ReadSecretFile(std::filesystem::temp_directory_path().string(), "--tls_ca")
                              .status()
                              .message()),
              HasSubstr("is a folder"));
  ClientSecurityOptions client;
  client.tls.ca_file = WriteFile("meshseek_ca_placeholder.pem", "not checked here");
  client.token_file = WriteFile("meshseek_blank_token", " \n\t\n");
  auto credentials = MakeChannelCredentials(client);
  ASSERT_FALSE(credentials.ok());
  EXPECT_THAT(std::string(credentials.status().message()), HasSubstr("only whitespace"));
  client.token_file = WriteFile("meshseek_spaced_token", "two words\n");
  EXPECT_THAT(std::string(MakeChannelCredentials(client).status().message()),
              HasSubstr("printable ASCII"));
  client.token_file = WriteFile("meshseek_good_token", "s3cret-token\n");
  EXPECT_TRUE(MakeChannelCredentials(client).ok());
}

TEST(CredentialsTest, ConstantTimeEquals) {
  EXPECT_TRUE(ConstantTimeEquals("Bearer abc", "Bearer abc"));
  EXPECT_FALSE(ConstantTimeEquals("Bearer abd", "Bearer abc"));
  EXPECT_FALSE(ConstantTimeEquals("Bearer ab", "Bearer abc"));
  EXPECT_FALSE(ConstantTimeEquals("Bearer abcd", "Bearer abc"));
  EXPECT_FALSE(ConstantTimeEquals("", "Bearer abc"));
  EXPECT_TRUE(ConstantTimeEquals("", ""));
}

}  // namespace
}  // namespace meshseek::rpc
