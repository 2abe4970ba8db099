#!/usr/bin/env bash
# Creates a DDS Security setup for coloc in OUT_DIR, as a road operator would: one CA that signs the
# identities of the roadside units and the vehicle and the governance and permissions documents.
# Permissions let each RSU publish only its own fix topics (addressed and unaddressed) and read its LiDAR's frames and the
# CAMs, the roadside sensors (LiDAR drivers, the V2X bridge) publish only those, and the vehicle publish only its dimensions.
#
#   scripts/make-dds-security.sh OUT_DIR [RSU_ID ...]      (default RSUs: rsu_a rsu_b)
#
# Files per participant NAME: NAME.pem, NAME_key.pem, NAME_permissions.p7s; shared: identity_ca.pem,
# permissions_ca.pem (the same CA here), governance.p7s. `coloc rsu-listen|rsu-publish --security
# OUT_DIR --name NAME` uses them. Also made, for tests: OUT_DIR/rogue/ with `intruder_rogue` (a whole
# setup under a CA the vehicle does not trust) and `intruder_listed` (a trusted identity permitted to
# subscribe only).
set -euo pipefail
out=${1:?usage: make-dds-security.sh OUT_DIR [RSU_ID ...]}
shift
rsus=("$@")
[ ${#rsus[@]} -gt 0 ] || rsus=(rsu_a rsu_b)
mkdir -p "$out"
cd "$out"
days=3650
not_before=$(date -u +%Y-%m-%dT%H:%M:%S -d '1 day ago')
not_after=$(date -u +%Y-%m-%dT%H:%M:%S -d '10 years')

make_ca() {  # name subject
  openssl ecparam -name prime256v1 -genkey -noout -out "$1_key.pem"
  openssl req -x509 -new -key "$1_key.pem" -days $days -subj "$2" -out "$1.pem" 2>/dev/null
}
make_identity() {  # name ca
  openssl ecparam -name prime256v1 -genkey -noout -out "$1_key.pem"
  openssl req -new -key "$1_key.pem" -subj "/CN=$1" -out "$1.csr" 2>/dev/null
  openssl x509 -req -in "$1.csr" -CA "$2.pem" -CAkey "$2_key.pem" -CAcreateserial -days $days -out "$1.pem" 2>/dev/null
  rm -f "$1.csr"
}
grant() {  # name publish-topics subscribe-topics
  local pub="" sub="" t
  for t in $2; do pub="$pub<topic>$t</topic>"; done
  for t in $3; do sub="$sub<topic>$t</topic>"; done
  cat <<XML
    <grant name="$1">
      <subject_name>CN=$1</subject_name>
      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
        $( [ -n "$pub" ] && echo "<publish><topics>$pub</topics></publish>" )
        $( [ -n "$sub" ] && echo "<subscribe><topics>$sub</topics></subscribe>" )
      </allow_rule>
      <default>DENY</default>
    </grant>
XML
}
sign() {  # file ca
  openssl smime -sign -in "$1.xml" -text -out "$1.p7s" -signer "$2.pem" -inkey "$2_key.pem"
}
permissions() {  # name publish subscribe ca
  { echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="omg_shared_ca_permissions.xsd">'
    echo '  <permissions>'
    grant "$1" "$2" "$3"
    echo '  </permissions>'
    echo '</dds>'; } > "$1_permissions.xml"
  sign "$1_permissions" "$4"
}

make_ca operator_ca "/CN=coloc road operator CA"
cp operator_ca.pem identity_ca.pem
cp operator_ca.pem permissions_ca.pem

cat > governance.xml <<XML
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML
sign governance operator_ca

fix_topics=""
sensor_topics="rt/v2x/cam"
for id in "${rsus[@]}"; do
  make_identity "$id" operator_ca
  # The RSU's node (coloc rsu-node) reads its own LiDAR's frames and the CAMs.
  permissions "$id" "rt/rsu/$id/addressed_fix rt/rsu/$id/fix" "rt/vehicle/dimensions rt/rsu/$id/points rt/v2x/cam" operator_ca
  fix_topics="$fix_topics rt/rsu/$id/addressed_fix rt/rsu/$id/fix"
  sensor_topics="$sensor_topics rt/rsu/$id/points"
done
# What feeds the RSU nodes at the roadside: the LiDARs' drivers and the V2X stack's bridge.
make_identity roadside_sensors operator_ca
permissions roadside_sensors "$sensor_topics" "" operator_ca
make_identity vehicle operator_ca
permissions vehicle "rt/vehicle/dimensions" "$fix_topics" operator_ca

# An intruder with its own CA, which the vehicle does not trust: a complete setup of its own in rogue/.
mkdir -p rogue
(
  cd rogue
  make_ca rogue_ca "/CN=rogue CA"
  cp rogue_ca.pem identity_ca.pem
  cp rogue_ca.pem permissions_ca.pem
  cp ../governance.xml governance.xml
  sign governance rogue_ca
  make_identity intruder_rogue rogue_ca
  permissions intruder_rogue "rt/rsu/${rsus[0]}/addressed_fix rt/rsu/${rsus[0]}/fix" "" rogue_ca
  rm -f ./*.srl
)
# An intruder the operator knows, allowed to listen to fixes but not to send them.
make_identity intruder_listed operator_ca
permissions intruder_listed "" "$fix_topics" operator_ca
rm -f ./*.srl
echo "DDS Security files in $out: CA, ${rsus[*]}, roadside_sensors, vehicle, intruder_rogue, intruder_listed"
