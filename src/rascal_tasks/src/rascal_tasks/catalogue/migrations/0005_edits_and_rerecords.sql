-- RASCAL catalogue, version 5: corrections by a person, with an audit trail (`rascal edit`).
-- Each changed field of a sherd is one row here, written in the same transaction as the change
-- itself: who, when, which field, the old and the new value (JSON, so a number stays a number
-- and "none" stays null) and why. Rows are never changed or deleted (the trigger below), so a
-- value is never overwritten without a trace. Depends only on the sherds table (0001).
-- Also: a lost sherd found again and recorded afresh into its own row (`rascal rerecord`).

CREATE TABLE sherd_edits (
    edit_id    bigserial PRIMARY KEY,
    sherd_id   bigint NOT NULL REFERENCES sherds (sherd_id),
    -- the fields changed by one `rascal edit` share it
    change_id  uuid NOT NULL,
    at         timestamptz NOT NULL,
    who        text NOT NULL CHECK (btrim(who) <> '' AND length(who) <= 64),
    field      text NOT NULL CHECK (field ~ '^[a-z][a-z0-9_]{0,62}$'),
    old_value  jsonb NOT NULL,
    new_value  jsonb NOT NULL,
    reason     text NOT NULL CHECK (btrim(reason) <> '' AND length(reason) <= 500)
);

CREATE INDEX sherd_edits_sherd ON sherd_edits (sherd_id, edit_id);

CREATE FUNCTION sherd_edits_append_only() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    RAISE EXCEPTION 'sherd_edits is an audit trail: rows are only ever added'
        USING ERRCODE = 'insufficient_privilege';
END
$$;

CREATE TRIGGER sherd_edits_no_update_or_delete
    BEFORE UPDATE OR DELETE ON sherd_edits
    FOR EACH ROW EXECUTE FUNCTION sherd_edits_append_only();

CREATE TRIGGER sherd_edits_no_truncate
    BEFORE TRUNCATE ON sherd_edits
    FOR EACH STATEMENT EXECUTE FUNCTION sherd_edits_append_only();

-- A lost sherd put back on the mat and recorded again (`rascal rerecord`): its new row in the same
-- context, once. The row is made when the re-record starts (new_sherd_id NULL, after_seq the
-- context's last number then), so a re-record stopped halfway is carried on, and linked when the
-- batch has recorded exactly one new sherd. The lost row stays as it was.
CREATE TABLE sherd_rerecords (
    lost_sherd_id  bigint PRIMARY KEY REFERENCES sherds (sherd_id),
    after_seq      integer NOT NULL CHECK (after_seq >= 1),
    new_sherd_id   bigint UNIQUE REFERENCES sherds (sherd_id)
                   CHECK (new_sherd_id <> lost_sherd_id),
    started_at     timestamptz NOT NULL,
    linked_at      timestamptz CHECK ((linked_at IS NULL) = (new_sherd_id IS NULL)),
    who            text NOT NULL CHECK (btrim(who) <> '' AND length(who) <= 64)
);
