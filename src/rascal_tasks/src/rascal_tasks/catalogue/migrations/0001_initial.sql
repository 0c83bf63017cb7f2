-- RASCAL catalogue, version 1: sites, contexts, sherds and the event log.
-- Applied by `rascal db migrate` inside one transaction; never edit after release (add 0002_*).
-- Units: mass in grams, lengths in millimetres, durations in seconds, positions in metres
-- (base_link), colour L*a*b* in D50.

-- An identifier of a site or a context: what validate_context_id() accepts, enforced again here.
CREATE DOMAIN rascal_code AS text
    CHECK (VALUE ~ '^[A-Za-z0-9_][A-Za-z0-9._-]{0,63}$');

CREATE TABLE sites (
    site_id     rascal_code PRIMARY KEY,
    name        text,
    created_at  timestamptz NOT NULL DEFAULT now()
);

-- A context (stratigraphic unit / bag) whose sherds are recorded together.
CREATE TABLE contexts (
    context_id  rascal_code PRIMARY KEY,
    site_id     rascal_code NOT NULL REFERENCES sites (site_id),
    description text,
    created_at  timestamptz NOT NULL DEFAULT now()
);

CREATE TYPE sherd_status AS ENUM ('picked', 'weighed', 'photographed', 'done', 'lost');

CREATE TABLE sherds (
    sherd_id          bigserial PRIMARY KEY,
    context_id        rascal_code NOT NULL REFERENCES contexts (context_id),
    seq               integer NOT NULL CHECK (seq >= 1),
    status            sherd_status NOT NULL DEFAULT 'picked',
    -- where it was picked up (base_link, metres) and how hard it was
    pickup_x_m        double precision,
    pickup_y_m        double precision,
    grasp_attempts    integer NOT NULL DEFAULT 0 CHECK (grasp_attempts >= 0),
    drops             integer NOT NULL DEFAULT 0 CHECK (drops >= 0),
    -- measurements
    mass_g            double precision CHECK (mass_g > 0),
    length_mm         double precision CHECK (length_mm > 0),
    width_mm          double precision CHECK (width_mm > 0),
    thickness_mm      double precision CHECK (thickness_mm > 0),
    colour_munsell    text,
    colour_l          double precision,
    colour_a          double precision,
    colour_b          double precision,
    chart_delta_e00   double precision CHECK (chart_delta_e00 >= 0),
    px_per_cm         double precision CHECK (px_per_cm > 0),
    -- the archival image, relative to the archive root, and its SHA-256 (lower-case hex)
    image_path        text,
    image_sha256      text CHECK (image_sha256 ~ '^[0-9a-f]{64}$'),
    -- per-phase durations (simulated seconds on the simulator)
    t_pick_s          double precision CHECK (t_pick_s >= 0),
    t_weigh_s         double precision CHECK (t_weigh_s >= 0),
    t_photo_s         double precision CHECK (t_photo_s >= 0),
    t_discard_s       double precision CHECK (t_discard_s >= 0),
    -- provenance
    rig               text NOT NULL,
    software_version  text NOT NULL,
    config_hash       text NOT NULL,
    lost_reason       text,
    notes             text,
    -- when each state was reached (from the recorder's clock)
    picked_at         timestamptz NOT NULL,
    weighed_at        timestamptz,
    photographed_at   timestamptz,
    done_at           timestamptz,
    lost_at           timestamptz,
    updated_at        timestamptz NOT NULL,
    -- gap-free numbering per context: the number is taken inside the inserting transaction
    CONSTRAINT sherds_context_seq_unique UNIQUE (context_id, seq),
    -- a state implies what was recorded to reach it
    CONSTRAINT sherds_weighed_has_mass CHECK (
        status NOT IN ('weighed', 'photographed', 'done') OR mass_g IS NOT NULL),
    CONSTRAINT sherds_photographed_has_image CHECK (
        status NOT IN ('photographed', 'done')
        OR (image_path IS NOT NULL AND image_sha256 IS NOT NULL)),
    CONSTRAINT sherds_lost_has_reason CHECK (status <> 'lost' OR lost_reason IS NOT NULL)
);

CREATE INDEX sherds_unfinished ON sherds (context_id, seq)
    WHERE status IN ('picked', 'weighed', 'photographed');

-- Everything that happened, in order: one row per state change, drop, resume, note.
CREATE TABLE events (
    event_id    bigserial PRIMARY KEY,
    at          timestamptz NOT NULL,
    context_id  rascal_code REFERENCES contexts (context_id),
    sherd_id    bigint REFERENCES sherds (sherd_id),
    kind        text NOT NULL CHECK (kind ~ '^[a-z_]{1,32}$'),
    rig         text,
    detail      jsonb NOT NULL DEFAULT '{}'::jsonb
);

CREATE INDEX events_context_at ON events (context_id, at);
CREATE INDEX events_sherd ON events (sherd_id);
