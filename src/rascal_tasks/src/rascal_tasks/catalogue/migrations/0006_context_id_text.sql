-- RASCAL catalogue, version 6: context IDs as excavations write them (issue 19).
-- A context ID is any printable text of 1..64 characters, NFC-normalised, without control
-- characters, not blank, no space at either end, no '.' or '..' path part
-- (context_id.validate_context_id says which rule a value breaks; this repeats the rules).
-- Site IDs keep the old small alphabet, now as a CHECK on sites (the domain is shared).
-- The archive folder of a context is derived from its ID (context_id.context_folder); IDs of the
-- old alphabet keep their folder, so nothing on disk moves. Independent of every other migration.

ALTER DOMAIN rascal_code DROP CONSTRAINT rascal_code_check;

ALTER DOMAIN rascal_code ADD CONSTRAINT rascal_code_check CHECK (
    char_length(VALUE) BETWEEN 1 AND 64
    AND VALUE IS NFC NORMALIZED
    AND VALUE !~ '[\x01-\x1f\x7f-\x9f]'
    AND btrim(VALUE) = VALUE
    AND VALUE !~ '(^|[/\\])\.\.?($|[/\\])'
);

ALTER TABLE sites ADD CONSTRAINT sites_site_id_code
    CHECK (site_id ~ '^[A-Za-z0-9_][A-Za-z0-9._-]{0,63}$');
