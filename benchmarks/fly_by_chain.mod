MODULE FlyByChain
    ! The long fly-by chain of issue 36 on the IRB 120: eight joint moves back and forth between
    ! a feeder on the right and a tray on the left, each pass through a target within a z10 zone,
    ! one stop at the feeder per cycle (about 5.4 s). benchmarks/cycle_examples.py --chain.
    PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.5, [0, 0, 40], [1, 0, 0, 0], 0, 0, 0]];
    CONST robtarget pFeed := [[380, -210, 260], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pTray := [[340, 230, 300], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];

    PROC main()
        WHILE TRUE DO
            MoveJ pTray, v1000, z10, tGripper;
            MoveJ pFeed, v1000, z10, tGripper;
            MoveJ pTray, v1000, z10, tGripper;
            MoveJ pFeed, v1000, z10, tGripper;
            MoveJ pTray, v1000, z10, tGripper;
            MoveJ pFeed, v1000, z10, tGripper;
            MoveJ pTray, v1000, z10, tGripper;
            MoveJ pFeed, v1000, fine, tGripper;
        ENDWHILE
    ENDPROC
ENDMODULE
