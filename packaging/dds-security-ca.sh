#!/usr/bin/env bash
# A complete DDS Security test setup for mixpilot's instructor (SPEC §10, docs/instructor-security.md),
# made with openssl into DIR. Installed by the Debian package as /usr/bin/mixpilot-security-ca;
# in the source tree packaging/dds-security-ca.sh. --help says what it makes.
set -euo pipefail

me=$(basename "$0")
help() {
  cat <<EOF
usage: $me DIR [--force] [--days N]

A complete DDS Security test setup for mixpilot's instructor (mixpilot fly --instructor,
mixpilot instruct; docs/instructor-security.md in mixpilot's source says how a training
centre makes its own), made with openssl into DIR: a training centre's identity CA and
permissions CA, the signed governance, and one folder per identity that --dds-security
FOLDER takes:

  DIR/ca/                      the CAs' keys and certificates (keep the keys off the stations)
  DIR/governance.xml           the rules of the domain (signed copy in each identity folder)
  DIR/instructor/              may publish instructor commands, reads every station
  DIR/trainee-a/, trainee-b/   stations: publish telemetry and announcements, read commands
  DIR/other-ca/                an "instructor" of a CA the centre does not know (its own
                               identity CA, permissions CA and signed documents)
  DIR/expired/                 an instructor whose certificate expired yesterday

Each identity folder holds identity_ca.pem, cert.pem, key.pem, permissions_ca.pem,
governance.p7s, permissions.xml, permissions.p7s and cyclonedds.xml (the loopback-only
configuration with its Security section, for CYCLONEDDS_URI). Keys are EC prime256v1.
Everything is bound to loopback: interface lo, multicast off, the peer 127.0.0.1.

  --force     replace an existing setup in DIR
  --days N    how long the certificates and permissions are valid (default 365)
  -h, --help  this text

exit status: 0 made, 1 failure (openssl missing, DIR already holds a setup), 2 usage
EOF
}
usage() { echo "usage: $me DIR [--force] [--days N] (--help says more)" >&2; exit 2; }
dir= force=0 days=365
while [ $# -gt 0 ]; do
  case "$1" in
    --force) force=1 ;;
    --days) [ $# -ge 2 ] || usage; days="$2"; shift ;;
    -h|--help) help; exit 0 ;;
    -*) usage ;;
    *) [ -z "$dir" ] || usage; dir="$1" ;;
  esac
  shift
done
[ -n "$dir" ] || usage
case "$days" in ''|*[!0-9]*) echo "$me: --days expects a whole number of days, got '$days'" >&2; exit 2 ;; esac
[ "$days" -ge 1 ] || { echo "$me: --days expects at least 1" >&2; exit 2; }
command -v openssl >/dev/null || { echo "$me: openssl is missing (apt-get install openssl)" >&2; exit 1; }
if [ -e "$dir/ca" ] && [ "$force" -ne 1 ]; then
  echo "$me: $dir already holds a setup (--force replaces it)" >&2
  exit 1
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
rm -rf "$dir/ca" "$dir/instructor" "$dir/trainee-a" "$dir/trainee-b" "$dir/other-ca" \
       "$dir/expired" "$dir/governance.xml"
mkdir -p "$dir/ca"
ca="$dir/ca"
org="mixpilot training centre"

# Debian's Cyclone DDS 0.10 security plugins (package libddsc0debian).
plugins=/usr/lib/x86_64-linux-gnu/libddsc0debian
for p in auth ac crypto; do
  [ -f "$plugins/libdds_security_$p.so" ] ||
    echo "$me: warning: $plugins/libdds_security_$p.so is missing (package libddsc0debian)" >&2
done

key() { openssl ecparam -name prime256v1 -genkey -noout -out "$1" 2>/dev/null; chmod 600 "$1"; }
self_signed() {  # KEY CERT SUBJECT
  openssl req -x509 -new -key "$1" -out "$2" -days $((days * 4)) -subj "$3" -sha256 \
    -addext basicConstraints=critical,CA:TRUE \
    -addext keyUsage=critical,keyCertSign,cRLSign,digitalSignature
}
# A minimal `openssl ca` setup for CA NAME (its key and certificate in $ca): it signs with any
# start and end date, which `openssl x509 -req` cannot in OpenSSL 3.0.
ca_config() {
  local name="$1"
  mkdir -p "$ca/$name.db"
  : >"$ca/$name.db/index.txt"
  echo 1000 >"$ca/$name.db/serial"
  cat >"$ca/$name.cnf" <<EOF
[ ca ]
default_ca = this
[ this ]
dir = $ca/$name.db
database = \$dir/index.txt
serial = \$dir/serial
new_certs_dir = \$dir
certificate = $ca/$name.pem
private_key = $ca/$name.key
default_md = sha256
policy = anything
unique_subject = no
copy_extensions = none
x509_extensions = identity
[ anything ]
countryName = optional
organizationName = optional
commonName = supplied
[ identity ]
basicConstraints = critical,CA:FALSE
keyUsage = critical,digitalSignature,keyAgreement
EOF
}
sign_identity() {  # CA NAME SUBJECT [START END] -> $dir/NAME/{key,cert}.pem
  local signer="$1" name="$2" subject="$3"
  mkdir -p "$dir/$name"
  key "$dir/$name/key.pem"
  openssl req -new -key "$dir/$name/key.pem" -out "$ca/$name.csr" -subj "$subject"
  local dates=(-days "$days")
  [ $# -ge 5 ] && dates=(-startdate "$4" -enddate "$5")
  openssl ca -batch -notext -config "$ca/$signer.cnf" -in "$ca/$name.csr" \
    -out "$dir/$name/cert.pem" "${dates[@]}" 2>/dev/null
}
smime_sign() {  # CA IN OUT: an S/MIME (PKCS#7, multipart/signed) signature by CA, as DDS Security wants
  openssl smime -sign -in "$2" -text -out "$3" -signer "$ca/$1.pem" -inkey "$ca/$1.key"
}
iso() { date -u -d "$1" +%Y-%m-%dT%H:%M:%S; }

# The centre's two CAs, and a stranger's.
key "$ca/identity_ca.key"
self_signed "$ca/identity_ca.key" "$ca/identity_ca.pem" "/C=NL/O=$org/CN=mixpilot identity CA"
key "$ca/permissions_ca.key"
self_signed "$ca/permissions_ca.key" "$ca/permissions_ca.pem" "/C=NL/O=$org/CN=mixpilot permissions CA"
key "$ca/other_ca.key"
self_signed "$ca/other_ca.key" "$ca/other_ca.pem" "/C=NL/O=another school/CN=another identity CA"
ca_config identity_ca
ca_config other_ca

# Identities.
sign_identity identity_ca instructor "/C=NL/O=$org/CN=instructor"
sign_identity identity_ca trainee-a "/C=NL/O=$org/CN=trainee-a"
sign_identity identity_ca trainee-b "/C=NL/O=$org/CN=trainee-b"
sign_identity other_ca other-ca "/C=NL/O=$org/CN=instructor"
sign_identity identity_ca expired "/C=NL/O=$org/CN=expired instructor" \
  "$(date -u -d '-10 days' +%Y%m%d%H%M%SZ)" "$(date -u -d '-1 day' +%Y%m%d%H%M%SZ)"

# The governance: every domain; only authenticated participants; the instructor's command
# topic with read and write access control, encrypted; the stations' telemetry and
# announcements written only by those allowed, signed, readable by any authenticated peer; any
# other topic (a pilot's Joy, a remote vehicle) among authenticated peers.
cat >"$dir/governance.xml" <<'EOF'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>SIGN</discovery_protection_kind>
      <liveliness_protection_kind>SIGN</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>rt/mixpilot/instructor/*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>SIGN</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
        <topic_rule>
          <topic_expression>rt/mixpilot/*</topic_expression>
          <enable_discovery_protection>false</enable_discovery_protection>
          <enable_liveliness_protection>false</enable_liveliness_protection>
          <enable_read_access_control>false</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>NONE</metadata_protection_kind>
          <data_protection_kind>SIGN</data_protection_kind>
        </topic_rule>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>false</enable_discovery_protection>
          <enable_liveliness_protection>false</enable_liveliness_protection>
          <enable_read_access_control>false</enable_read_access_control>
          <enable_write_access_control>false</enable_write_access_control>
          <metadata_protection_kind>NONE</metadata_protection_kind>
          <data_protection_kind>NONE</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF

# A permissions document for NAME (granting RULES, XML) signed by PERMISSIONS_CA; the subject is
# the certificate's, as Cyclone compares it (RFC 2253).
permissions() {  # NAME PERMISSIONS_CA RULES
  local name="$1" signer="$2" rules="$3" subject
  subject=$(openssl x509 -in "$dir/$name/cert.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//')
  local from until
  from=$(iso '-1 day') until=$(iso "+$days days")
  cat >"$dir/$name/permissions.xml" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$name">
      <subject_name>$subject</subject_name>
      <validity><not_before>$from</not_before><not_after>$until</not_after></validity>
$rules
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
EOF
  smime_sign "$signer" "$dir/$name/permissions.xml" "$dir/$name/permissions.p7s"
}
domains='<domains><id_range><min>0</min><max>230</max></id_range></domains>'
instructor_rules="      <allow_rule>
        $domains
        <publish><topics><topic>rt/mixpilot/instructor/command</topic></topics></publish>
        <subscribe><topics><topic>*</topic></topics></subscribe>
      </allow_rule>"
# A station reads instructor commands and may not write them; it writes its telemetry and
# announcements, and whatever else a station talks (Joy, a remote vehicle). Cyclone 0.10 lets a
# participant create a topic by the first rule that names it, publish or subscribe alike: the
# rule that allows reading the command topic comes before the one that denies writing it (a
# deny first would refuse the topic itself), and that deny before the allow of everything.
trainee_rules="      <allow_rule>
        $domains
        <subscribe><topics><topic>rt/mixpilot/instructor/*</topic></topics></subscribe>
      </allow_rule>
      <deny_rule>
        $domains
        <publish><topics><topic>rt/mixpilot/instructor/*</topic></topics></publish>
      </deny_rule>
      <allow_rule>
        $domains
        <publish><topics><topic>*</topic></topics></publish>
        <subscribe><topics><topic>*</topic></topics></subscribe>
      </allow_rule>"

# Each identity folder: its trust anchors, the signed documents, its Cyclone configuration.
finish() {  # NAME IDENTITY_CA PERMISSIONS_CA RULES
  local name="$1" idca="$2" permca="$3" rules="$4"
  cp "$ca/$idca.pem" "$dir/$name/identity_ca.pem"
  cp "$ca/$permca.pem" "$dir/$name/permissions_ca.pem"
  smime_sign "$permca" "$dir/governance.xml" "$dir/$name/governance.p7s"
  permissions "$name" "$permca" "$rules"
  local f="$dir/$name"
  cat >"$f/cyclonedds.xml" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- mixpilot's loopback-only configuration (assets/dds-loopback.xml) with DDS Security for the
     identity "$name" (made by mixpilot-security-ca). -->
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <General>
      <Interfaces><NetworkInterface name="lo"/></Interfaces>
      <AllowMulticast>false</AllowMulticast>
    </General>
    <Discovery>
      <ParticipantIndex>auto</ParticipantIndex>
      <MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>
      <Peers><Peer address="127.0.0.1"/></Peers>
    </Discovery>
    <Security>
      <Authentication>
        <Library path="$plugins/libdds_security_auth.so" initFunction="init_authentication" finalizeFunction="finalize_authentication"/>
        <IdentityCA>file:$f/identity_ca.pem</IdentityCA>
        <IdentityCertificate>file:$f/cert.pem</IdentityCertificate>
        <PrivateKey>file:$f/key.pem</PrivateKey>
      </Authentication>
      <Cryptographic>
        <Library path="$plugins/libdds_security_crypto.so" initFunction="init_crypto" finalizeFunction="finalize_crypto"/>
      </Cryptographic>
      <AccessControl>
        <Library path="$plugins/libdds_security_ac.so" initFunction="init_access_control" finalizeFunction="finalize_access_control"/>
        <PermissionsCA>file:$f/permissions_ca.pem</PermissionsCA>
        <Governance>file:$f/governance.p7s</Governance>
        <Permissions>file:$f/permissions.p7s</Permissions>
      </AccessControl>
    </Security>
  </Domain>
</CycloneDDS>
EOF
}
finish instructor identity_ca permissions_ca "$instructor_rules"
finish trainee-a identity_ca permissions_ca "$trainee_rules"
finish trainee-b identity_ca permissions_ca "$trainee_rules"
finish expired identity_ca permissions_ca "$instructor_rules"
# The stranger signs its own documents: its permissions grant itself the instructor's rights.
ca_config other_permissions >/dev/null
cp "$ca/other_ca.key" "$ca/other_permissions.key"
cp "$ca/other_ca.pem" "$ca/other_permissions.pem"
finish other-ca other_ca other_permissions "$instructor_rules"
rm -f "$ca"/*.csr

for name in instructor trainee-a trainee-b other-ca expired; do
  printf '%s: %-11s %s (valid until %s)\n' "$me" "$name" "$dir/$name" \
    "$(openssl x509 -in "$dir/$name/cert.pem" -noout -enddate | sed 's/notAfter=//')"
done
