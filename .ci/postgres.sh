# Sourced by .ci/run: install Debian's PostgreSQL if it is missing, start a throwaway server on loopback
# and export SB3_GQN_POSTGRES_URL for the Optuna storage test (tests/test_zoo.py). `stop_postgres` stops it.
pg_bin() { ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1; }
if [ -z "$(pg_bin)" ]; then
    echo "== installing Debian's postgresql package"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq && apt-get install -y -qq postgresql >/dev/null
fi
PG_BIN="$(pg_bin)"
PG_DIR="$(mktemp -d /tmp/sb3-gqn-postgres.XXXXXX)"
PG_PORT="${SB3_GQN_POSTGRES_PORT:-55432}"
if [ "$(id -u)" = 0 ]; then  # initdb refuses to run as root
    chown postgres "$PG_DIR"
    PG_AS=(runuser -u postgres --)
else
    PG_AS=()
fi
"${PG_AS[@]}" "$PG_BIN/initdb" -D "$PG_DIR/data" -U sb3gqn --auth=trust >/dev/null
"${PG_AS[@]}" "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -l "$PG_DIR/server.log" -w \
    -o "-p $PG_PORT -k $PG_DIR -c listen_addresses=127.0.0.1" start >/dev/null
"${PG_AS[@]}" "$PG_BIN/createdb" -h 127.0.0.1 -p "$PG_PORT" -U sb3gqn optuna
export SB3_GQN_POSTGRES_URL="postgresql://sb3gqn@127.0.0.1:$PG_PORT/optuna"
echo "== PostgreSQL $("$PG_BIN/postgres" --version | awk '{print $3}') at $SB3_GQN_POSTGRES_URL"
stop_postgres() { "${PG_AS[@]}" "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -m fast -w stop >/dev/null || true; rm -rf "$PG_DIR"; }
