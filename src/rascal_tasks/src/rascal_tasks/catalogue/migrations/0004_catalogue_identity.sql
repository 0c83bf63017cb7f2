-- RASCAL catalogue, version 4: the catalogue's identity, one row per database.
-- Archived images are named <context>/<seq>-<first 12 hex digits of catalogue_id>.png, so two
-- catalogues (two databases) recording the same context ID into one archive folder never
-- overwrite each other's files. Rows written before this migration keep their image_path.
-- A copy of the database (CREATE DATABASE ... TEMPLATE, a restore on another server) is told
-- apart by database_name and system_identifier and takes a new catalogue_id when first used
-- (Catalogue.identity). Independent of every other migration.

CREATE TABLE catalogue_identity (
    only_row          boolean PRIMARY KEY DEFAULT true CHECK (only_row),
    catalogue_id      uuid NOT NULL,
    database_name     text NOT NULL,
    -- pg_control_system().system_identifier of the server; NULL where the role may not read it
    system_identifier bigint,
    created_at        timestamptz NOT NULL DEFAULT now()
);

INSERT INTO catalogue_identity (catalogue_id, database_name)
    VALUES (gen_random_uuid(), current_database());

DO $$
BEGIN
    UPDATE catalogue_identity
        SET system_identifier = (SELECT system_identifier FROM pg_control_system());
EXCEPTION WHEN insufficient_privilege THEN
    NULL;  -- identity() tries again; database_name still tells copies apart
END
$$;
