-- RASCAL catalogue, version 7: several rigs, one central catalogue (issue 20).
-- Each rig writes to its own PostgreSQL; a central server subscribes to every rig's publication
-- (PostgreSQL logical replication, central.py). For that, keys must never collide across rigs:
--  * every rig has a node number (rig_node.node_no), given by the central server when the rig
--    joins (`rascal central add-rig`); 0 is a rig that never joined (numbering as before).
--  * node n owns the key block [n * 2^40 + 1, (n + 1) * 2^40 - 1] of sherd_id, event_id and
--    edit_id (rascal_join_node moves the rows a rig recorded before joining into its block and
--    bounds the sequences to it). 2^40 keys per rig, node numbers 1..8191: every key stays
--    below 2^53, exact in JSON readers that use doubles.
--  * a find ID (<context>-<seq>) is unique because a context is recorded by one rig at a time:
--    the rig claims it on the central server (context_claims); a rig taking over a context
--    numbers on after the last number of the rig before it (seq_floor).
-- context_claims and central_rigs are used on the central server; a rig keeps its own claims
-- in context_claims too. Neither is published. Independent of every other migration but 0001
-- and 0005 (the foreign keys made deferrable below).

CREATE TABLE rig_node (
    only_row     boolean PRIMARY KEY DEFAULT true CHECK (only_row),
    node_no      integer NOT NULL DEFAULT 0 CHECK (node_no BETWEEN 0 AND 8191),
    rig_name     text CHECK (rig_name ~ '^[a-z0-9_][a-z0-9_-]{0,39}$'),
    -- libpq DSN of the central server, for claims (NULL: this catalogue is standalone)
    central_dsn  text,
    joined_at    timestamptz
);

INSERT INTO rig_node DEFAULT VALUES;

-- On a rig: the contexts it holds or held. On the central server: who holds each context.
CREATE TABLE context_claims (
    context_id   rascal_code PRIMARY KEY,
    rig_name     text NOT NULL,
    -- held: claimed on the central server; provisional: claimed while the central server was
    -- unreachable (registered on the next contact); released: given up (last_seq set);
    -- clash: registered late while another rig held it (a person must look)
    state        text NOT NULL CHECK (state IN ('held', 'provisional', 'released', 'clash')),
    -- numbering starts after this (the last number of the rig that held it before)
    seq_floor    integer NOT NULL DEFAULT 0 CHECK (seq_floor >= 0),
    last_seq     integer CHECK (last_seq >= 0),
    claimed_at   timestamptz NOT NULL DEFAULT now(),
    released_at  timestamptz
);

-- On the central server: every rig that was added, with its node number.
CREATE TABLE central_rigs (
    rig_name      text PRIMARY KEY CHECK (rig_name ~ '^[a-z0-9_][a-z0-9_-]{0,39}$'),
    node_no       integer NOT NULL UNIQUE CHECK (node_no BETWEEN 1 AND 8191),
    subscription  text NOT NULL UNIQUE,
    -- the rig's DSN as the central server reaches it, password masked
    publisher     text NOT NULL,
    added_at      timestamptz NOT NULL DEFAULT now()
);

-- Renumbering a rig's rows into its block must change keys that other rows point to.
ALTER TABLE events ALTER CONSTRAINT events_sherd_id_fkey DEFERRABLE;
ALTER TABLE sherd_edits ALTER CONSTRAINT sherd_edits_sherd_id_fkey DEFERRABLE;
ALTER TABLE sherd_rerecords ALTER CONSTRAINT sherd_rerecords_lost_sherd_id_fkey DEFERRABLE;
ALTER TABLE sherd_rerecords ALTER CONSTRAINT sherd_rerecords_new_sherd_id_fkey DEFERRABLE;

-- The audit trail stays append-only, but for rascal_join_node moving its keys (and nothing else).
CREATE OR REPLACE FUNCTION sherd_edits_append_only() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    IF TG_OP = 'UPDATE' AND current_setting('rascal.renumbering', true) = 'on'
       AND (to_jsonb(NEW) - 'edit_id' - 'sherd_id') = (to_jsonb(OLD) - 'edit_id' - 'sherd_id') THEN
        RETURN NEW;
    END IF;
    RAISE EXCEPTION 'sherd_edits is an audit trail: rows are only ever added'
        USING ERRCODE = 'insufficient_privilege';
END
$$;

-- Join node n (once; the same n again does nothing): move every key into the node's block and
-- bound the sequences to it. Runs as the tables' owner, in the caller's transaction.
CREATE FUNCTION rascal_join_node(n integer, name text, central text) RETURNS bigint
LANGUAGE plpgsql AS $$
DECLARE
    cur integer;
    base bigint := n::bigint << 40;
    moved bigint := 0;
    t record;
    seq text;
    top bigint;
BEGIN
    IF n < 1 OR n > 8191 THEN
        RAISE EXCEPTION 'node number % out of range 1..8191', n;
    END IF;
    SELECT node_no INTO cur FROM rig_node FOR UPDATE;
    IF cur = n THEN
        UPDATE rig_node SET rig_name = name, central_dsn = central;
        RETURN 0;
    ELSIF cur <> 0 THEN
        RAISE EXCEPTION 'this catalogue is already node % of a central server, not %', cur, n;
    END IF;
    SET CONSTRAINTS events_sherd_id_fkey, sherd_edits_sherd_id_fkey,
        sherd_rerecords_lost_sherd_id_fkey, sherd_rerecords_new_sherd_id_fkey DEFERRED;
    PERFORM set_config('rascal.renumbering', 'on', true);
    UPDATE sherds SET sherd_id = sherd_id + base WHERE sherd_id < base;
    GET DIAGNOSTICS moved = ROW_COUNT;
    UPDATE events SET event_id = event_id + base WHERE event_id < base;
    UPDATE events SET sherd_id = sherd_id + base WHERE sherd_id < base;
    UPDATE sherd_edits SET edit_id = edit_id + base WHERE edit_id < base;
    UPDATE sherd_edits SET sherd_id = sherd_id + base WHERE sherd_id < base;
    UPDATE sherd_rerecords SET lost_sherd_id = lost_sherd_id + base WHERE lost_sherd_id < base;
    UPDATE sherd_rerecords SET new_sherd_id = new_sherd_id + base WHERE new_sherd_id < base;
    PERFORM set_config('rascal.renumbering', '', true);
    FOR t IN SELECT * FROM (VALUES ('sherds', 'sherd_id'), ('events', 'event_id'),
                                   ('sherd_edits', 'edit_id')) AS v (tab, col) LOOP
        seq := pg_get_serial_sequence(t.tab, t.col);
        EXECUTE format('SELECT COALESCE(max(%I), 0) FROM %I', t.col, t.tab) INTO top;
        top := GREATEST(top + 1, base + 1);
        EXECUTE format('ALTER SEQUENCE %s MINVALUE %s MAXVALUE %s START WITH %s RESTART WITH %s',
                       seq, base + 1, base + (1::bigint << 40) - 1, top, top);
    END LOOP;
    UPDATE rig_node SET node_no = n, rig_name = name, central_dsn = central, joined_at = now();
    RETURN moved;
END
$$;
