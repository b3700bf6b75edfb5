-- What each issued certificate was (issue 37): the customer and order it names, the hash of
-- the template (and logo) that typeset it, the SHA-256 of its PDF and of its JSON, and the
-- reason of an amendment. A number is bound to this content: a reissue must match it, other
-- content needs an amendment. Rows issued before this migration have NULLs and are bound to
-- their content at their next reissue.

ALTER TABLE certificates ADD COLUMN customer TEXT;
ALTER TABLE certificates ADD COLUMN order_ref TEXT;
ALTER TABLE certificates ADD COLUMN template_sha256 TEXT;
ALTER TABLE certificates ADD COLUMN pdf_sha256 TEXT;
ALTER TABLE certificates ADD COLUMN json_sha256 TEXT;
ALTER TABLE certificates ADD COLUMN reason TEXT;
