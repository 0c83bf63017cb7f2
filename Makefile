# The two commands of the README. Both do all set-up on a fresh Debian 12 machine (as root).
.PHONY: test demo setup build clean
test: setup
	bash scripts/test.sh
demo: setup
	RIG=$(RIG) bash scripts/demo.sh
setup:
	bash scripts/setup.sh
clean:
	rm -rf build devel .setup
