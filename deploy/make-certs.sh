#!/usr/bin/env bash
# Makes a private CA, one certificate for the meshseek services and a bearer
# token, with openssl (Debian's `openssl` package):
#   deploy/make-certs.sh DIR [NAME...]
# DIR/ca.crt          the CA every side verifies its peers against (--tls_ca)
# DIR/tls.crt, tls.key  the services' certificate (--tls_cert, --tls_key), valid
#                     for server and client use (mutual TLS), naming localhost,
#                     127.0.0.1, the compose and Kubernetes service names, and
#                     every NAME given
# DIR/token           a random bearer token (--token_file)
# ca.key stays in DIR: keep it off the cluster. Certificates last 365 days
# (MESHSEEK_CERT_DAYS). The tests call this with a temporary DIR for a
# throwaway CA. For Kubernetes, load them as the Secrets the manifests mount:
#   kubectl -n meshseek create secret generic meshseek-tls \
#     --from-file=ca.crt=DIR/ca.crt --from-file=tls.crt=DIR/tls.crt --from-file=tls.key=DIR/tls.key
#   kubectl -n meshseek create secret generic meshseek-token --from-file=token=DIR/token
set -euo pipefail
if [ $# -lt 1 ]; then
  echo "usage: $0 DIR [NAME...]" >&2
  exit 2
fi
DIR=$1
shift
DAYS=${MESHSEEK_CERT_DAYS:-365}
mkdir -p "$DIR"
chmod 700 "$DIR"
cd "$DIR"

ns=meshseek.svc.cluster.local
san="DNS:localhost,IP:127.0.0.1,IP:::1"
for name in coordinator resample extract codebook index index-0 index-1 \
            "coordinator.$ns" "resample.$ns" "extract.$ns" "codebook.$ns" "*.index.$ns" "$@"; do
  san="$san,DNS:$name"
done

# P-256 keys: small, fast handshakes, supported by every gRPC TLS stack.
openssl req -x509 -new -nodes -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 \
  -keyout ca.key -out ca.crt -days "$DAYS" -subj "/CN=meshseek CA $(date -u +%F)" \
  -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign" \
  2>/dev/null
openssl req -new -nodes -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 \
  -keyout tls.key -out tls.csr -subj "/CN=meshseek" 2>/dev/null
printf 'subjectAltName=%s\nextendedKeyUsage=serverAuth,clientAuth\nbasicConstraints=CA:FALSE\n' "$san" > tls.ext
openssl x509 -req -in tls.csr -CA ca.crt -CAkey ca.key -CAcreateserial -out tls.crt \
  -days "$DAYS" -extfile tls.ext 2>/dev/null
rm -f tls.csr tls.ext ca.srl
openssl rand -hex 32 > token
# The folder is private (700); the files are readable by the container user
# that compose's file secrets and Kubernetes' Secret volumes hand them to.
chmod 644 ca.crt tls.crt tls.key token
chmod 600 ca.key
echo "make-certs: $DIR/{ca.crt,tls.crt,tls.key,token}"
