MODULE RepeatedTargets
    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        WHILE TRUE DO
            MoveJ pA, v1000, z50, tool0;
            MoveJ pB, v1000, z50, tool0;
            MoveJ pA, v1000, z50, tool0;
            MoveJ pB, v1000, fine, tool0;
        ENDWHILE
    ENDPROC
ENDMODULE
