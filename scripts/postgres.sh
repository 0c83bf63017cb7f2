#!/usr/bin/env bash
# Starts Debian's PostgreSQL 15 cluster and makes sure the `rascal` role and database exist.
# Idempotent; used by setup.sh (tests, demo). On a field rig, point database.dsn in
# config/rascal.yaml at the lab's server instead.
#   scripts/postgres.sh start|stop|status|restart-if-running
set -euo pipefail
VER=15; CLUSTER=main
PORT=${RASCAL_PG_PORT:-5432}
case "${1:-start}" in
  start)
    if ! pg_lsclusters -h 2>/dev/null | awk '{print $1" "$2}' | grep -qx "$VER $CLUSTER"; then
      pg_createcluster -p "$PORT" "$VER" "$CLUSTER" >/dev/null
    fi
    if ! pg_lsclusters -h | awk -v v=$VER -v c=$CLUSTER '$1==v && $2==c {print $4}' | grep -q online; then
      pg_ctlcluster --skip-systemctl-redirect "$VER" "$CLUSTER" start
    fi
    port=$(pg_lsclusters -h | awk -v v=$VER -v c=$CLUSTER '$1==v && $2==c {print $3}')
    psql_() { su postgres -c "psql -p $port -v ON_ERROR_STOP=1 -qtA $*"; }
    if [ "$(psql_ "-c \"SELECT 1 FROM pg_roles WHERE rolname='rascal'\"")" != 1 ]; then
      # CREATEDB: the test suite makes a throw-away database per test session.
      psql_ "-c \"CREATE ROLE rascal LOGIN CREATEDB PASSWORD 'rascal'\""
    fi
    if [ "$(psql_ "-c \"SELECT 1 FROM pg_database WHERE datname='rascal'\"")" != 1 ]; then
      psql_ "-c \"CREATE DATABASE rascal OWNER rascal\""
    fi
    ;;
  stop) pg_ctlcluster --skip-systemctl-redirect "$VER" "$CLUSTER" stop ;;
  status) pg_lsclusters ;;
  restart-if-running)  # after apt upgraded the server: the running one still has the old binary
    # and fails on the new libraries ("plpgsql.so: undefined symbol"); no systemd restarts it
    if pg_lsclusters -h 2>/dev/null | awk -v v=$VER -v c=$CLUSTER '$1==v && $2==c {print $4}' \
        | grep -q online; then
      pg_ctlcluster --skip-systemctl-redirect "$VER" "$CLUSTER" restart
    fi
    ;;
  *) echo "usage: $0 start|stop|status|restart-if-running" >&2; exit 2 ;;
esac
