"""The RASCAL catalogue: PostgreSQL records of every sherd, and the image archive.

No ROS here: the connection, logger and clock are passed in.

    from rascal_tasks.catalogue import Catalogue, ImageArchive, migrate
"""

from .archive import ImageArchive
from .audit import EDITABLE, edit_sherd
from .backup import BackupError, create_backup, restore_backup
from .catalogue import SOFTWARE_VERSION, Catalogue, wait_for_database
from .context_id import MAX_ID_LENGTH, validate_context_id, validate_site_id
from .errors import (
    ArchiveError,
    CatalogueError,
    ConnectionLostError,
    ContextIdError,
    FieldError,
    MigrationError,
    StatusError,
)
from .export import export_records, parse_csv, to_csv, to_json
from .fields import COLUMN_TYPES, COLUMNS
from .integrity import repair_archive, verify_archive
from .migrate import available, migrate, status
from .queries import contexts_summary, find_sherd, parse_find_id, search_sherds, sherd_history
from .rerecord import link_rerecord, rerecord_links, start_rerecord

__all__ = [
    "Catalogue",
    "ImageArchive",
    "SOFTWARE_VERSION",
    "MAX_ID_LENGTH",
    "validate_context_id",
    "validate_site_id",
    "CatalogueError",
    "ContextIdError",
    "FieldError",
    "MigrationError",
    "StatusError",
    "ConnectionLostError",
    "ArchiveError",
    "wait_for_database",
    "repair_archive",
    "verify_archive",
    "export_records",
    "parse_csv",
    "to_csv",
    "to_json",
    "COLUMNS",
    "COLUMN_TYPES",
    "available",
    "migrate",
    "status",
    "EDITABLE",
    "edit_sherd",
    "BackupError",
    "create_backup",
    "restore_backup",
    "contexts_summary",
    "find_sherd",
    "parse_find_id",
    "search_sherds",
    "sherd_history",
    "start_rerecord",
    "link_rerecord",
    "rerecord_links",
]
